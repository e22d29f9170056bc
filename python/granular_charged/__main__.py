"""python3 -m granular_charged: the granular-charged command line."""
import sys

from .cli import main

sys.exit(main())
