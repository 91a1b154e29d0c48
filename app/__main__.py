"""``python -m app`` starts the GUI (same as ``radartune gui``)."""

import sys

from app.main import main

sys.exit(main())
