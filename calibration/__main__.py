"""``python -m spherecontact.calibration``: calibrate the model from the reference database."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
