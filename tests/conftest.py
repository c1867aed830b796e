"""Import studyapp before anything imports numba, so its cache directory is set (studyapp.numba_cache)."""

import studyapp  # noqa: F401
