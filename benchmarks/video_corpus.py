"""The real-camera clip corpus (issue 31): `fieldkit track`'s library on every clip.

Prints, clip by clip, the labelled contacts found and missed, false contacts, and
each labelled free flight's fitted g +/- its standard error (with the labelled scale
and capture-rate uncertainty) or the refusal. The clips are looked for as
tests/tracking/real_corpus.py says ($FIELDKIT_VIDEO_CORPUS first); their labels are
tests/data/video_corpus/*.labels.json.

    python benchmarks/video_corpus.py [CLIP ...]
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def _corpus_module():
    name = "fieldkit_real_corpus"
    spec = importlib.util.spec_from_file_location(
        name, REPO / "tests" / "tracking" / "real_corpus.py"
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def main(clips: list[str]) -> int:
    corpus = _corpus_module()
    folder = corpus.find_corpus()
    if folder is None:
        searched = ", ".join(str(p) for p in corpus.corpus_candidates())
        print(f"no clip corpus found (searched {searched})")
        return 1
    labels = [
        label for label in corpus.load_labels() if not clips or label["clip"] in clips
    ]
    print(f"corpus: {folder}, {len(labels)} labelled clips")
    results = []
    for label in labels:
        result = corpus.evaluate_clip(folder, label)
        print("\n".join(result.lines()), flush=True)
        results.append(result)
    print()
    print(corpus.result_table(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
