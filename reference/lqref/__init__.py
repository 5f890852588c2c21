"""lqref: Mitsuba 3 reference values for lightquad experiment files.

``python -m lqref <experiment files...> [--quick] [--out reference/values]``
writes one JSON file per experiment; see reference/README.md.

Generic: ``spec`` (reading a file, dispatching on its ``family`` tag),
``runner`` (values files, ``--check``), ``mitsuba3`` (importing Mitsuba),
``fnv`` (the hash) and ``__main__`` (the command line). Each equation family
has its module in ``lqref/families/`` (registered in ``families.FAMILIES``).
"""

from .fnv import file_hash, fnv1a64  # noqa: F401  (no Mitsuba needed)
