"""The hard rendered clips (video/hard.py): `fieldkit track`'s library on each.

Every failure mode of real footage (cast shadow, dark ball, motion blur, rolling
shutter, lens distortion, hand-held camera, phone compression, a block, dust, a
1000 fps free fall, a table bounce, all together) with exact truth. Prints, clip by
clip, the labelled contacts found and missed, false contacts, and each free flight's
fitted g +/- SE against 9.81, with the same checks as the real-camera corpus
(tests/tracking/real_corpus.py). Clips missing from DIR are rendered there first
(deterministic; about a minute a clip on 2 cores).

    python benchmarks/hard_clips.py [--dir out/hard] [CLIP ...]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def _module(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dir", type=Path, default=REPO / "out" / "hard")
    parser.add_argument("clips", nargs="*")
    args = parser.parse_args(argv)
    hard = _module("fieldkit_video_hard", REPO / "video" / "hard.py")
    corpus = _module("fieldkit_real_corpus", REPO / "tests/tracking/real_corpus.py")
    names = args.clips or [n for n in hard.CLIPS]
    results = []
    for name in names:
        labels = args.dir / f"{name}.labels.json"
        video = hard.clip_files(name, args.dir)[0]
        if not (labels.exists() and video.exists()):
            print(f"rendering {name} into {args.dir} ...", flush=True)
            hard.render_hard(name, args.dir)
        label = json.loads(labels.read_text())
        result = corpus.evaluate_video(video, label)
        print("\n".join(result.lines()), flush=True)
        results.append(result)
    print()
    print(corpus.result_table(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
