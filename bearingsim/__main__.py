import sys

from bearingsim.cli import main

sys.exit(main())
