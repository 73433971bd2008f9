"""``python -m cadgen``: the same command line as the ``cadgen`` script."""

from cadgen.cli import entry

if __name__ == "__main__":
    entry()
