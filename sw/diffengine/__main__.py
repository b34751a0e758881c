"""`python -m diffengine ...` = the `diffengine` command."""
import sys

from .cli import main

sys.exit(main())
