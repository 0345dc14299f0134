"""fieldkit: rockfall engineering, from field and video measurements to models.

The data flow (docs/architecture.md §1): ``io`` readers -> ``reduce`` (survey) or
``tracking`` (video) -> :class:`~fieldkit.impact_table.ImpactTable` -> figures
(``viz``), reports and, later, ``model`` / ``fit`` / ``diagnose`` / ``export``.
``physics`` holds the thesis equations as pure functions.
"""

from fieldkit.errors import FieldkitError
from fieldkit.impact_table import ImpactTable

__version__ = "0.1.0"
__all__ = ["FieldkitError", "ImpactTable", "__version__"]
