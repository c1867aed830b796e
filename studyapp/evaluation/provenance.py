"""Provenance of a result: what made it, from what, with which software.

Written into PARAMS.toml (and evaluation outputs) so a result can be traced
back: the command's settings, the input files' SHA-256 hashes, the seed, and
the versions of studyapp, Python and the numerical libraries.
"""

import datetime
import platform

import numba
import numpy
import scipy

from studyapp import __version__


def versions():
    return {
        "studyapp_version": __version__,
        "python_version": platform.python_version(),
        "numpy_version": numpy.__version__,
        "scipy_version": scipy.__version__,
        "numba_version": numba.__version__,
    }


def provenance(**settings):
    """A flat dict: creation time (UTC, ISO 8601), the given settings, then the software versions."""
    created = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
    return {"created": created, **settings, **versions()}
