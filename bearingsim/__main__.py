import sys

from bearingsim.cli import program

sys.exit(program())
