"""`python -m generator.cli`: the shadermatrix command line."""
import sys

from . import main

sys.exit(main())
