"""Entry point of Mitsuba 3 as a lightquad external estimator (lqref.serve),
runnable from any folder: ``reference/.venv/bin/python reference/serve.py``."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from lqref.serve import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
