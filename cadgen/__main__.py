"""``python -m cadgen``: the same command line as the ``cadgen`` script."""

from cadgen.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
