"""`python -m servoctl.cli`: the servoctl console script."""
import sys

from . import main

sys.exit(main())
