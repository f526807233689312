"""``python -m ttt_sm.cli``: the same as ``ttt-sm``."""

import sys

from . import main

sys.exit(main())
