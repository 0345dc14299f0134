"""fieldkit: rockfall engineering, from field and video measurements to models.

The data flow (docs/architecture.md §1): ``io`` readers -> ``reduce`` (survey) or
``tracking`` (video) -> :class:`~fieldkit.impact_table.ImpactTable` -> figures
(``viz``), reports and, later, ``model`` / ``fit`` / ``diagnose`` / ``export``.
``physics`` holds the thesis equations as pure functions.
"""

from fieldkit._version import __version__
from fieldkit.errors import FieldkitError
from fieldkit.impact_table import ImpactTable

__all__ = ["FieldkitError", "ImpactTable", "__version__"]
