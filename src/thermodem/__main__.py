"""``python -m thermodem ...``: the same command line as the ``thermodem`` script."""

from thermodem.cli import app

if __name__ == "__main__":
    app(prog_name="thermodem")
