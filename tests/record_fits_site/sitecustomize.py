"""With THERMOFRICTION_RECORD_FITS set, a command line started by a test records its identifications too
(tests/record_fits.py): on PYTHONPATH only for such a recording."""
import os
import sys

if os.environ.get("THERMOFRICTION_RECORD_FITS") and os.environ.get("PYTEST_CURRENT_TEST"):
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    import record_fits

    record_fits.install_in_child()
