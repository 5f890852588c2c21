"""lqref: Mitsuba 3 reference values for lightquad experiment files.

``python -m lqref <experiment files...> [--quick] [--out reference/values]``
writes one JSON file per experiment; see reference/README.md.
"""

from .fnv import file_hash, fnv1a64  # noqa: F401  (no Mitsuba needed)
