"""Provenance of a result: what made it, from what, with which software, on which machine.

Written into PARAMS.toml (and evaluation outputs) so a result can be traced
back: the command's settings, the input files' SHA-256 hashes, the seed, then
``studyapp.provenance.environment()`` (studyapp's version and commit, Python's
and the libraries' versions, the CPU and the BLAS kernels), flat, since
PARAMS.toml's ``[provenance]`` table holds no nested tables.
"""

import datetime

from studyapp.provenance import environment


def provenance(**settings):
    """A flat dict: creation time (UTC, ISO 8601), the given settings, then the environment."""
    created = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
    return {"created": created, **settings, **environment()}
