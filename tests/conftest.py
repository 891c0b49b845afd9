"""Test session set-up: the timeline cache lives in a folder of this session (a run never reads timelines
that another run, or another version of the code, wrote)."""

import os
import tempfile

if "LVGYM_CACHE_DIR" not in os.environ:
    os.environ["LVGYM_CACHE_DIR"] = tempfile.mkdtemp(prefix="lvgym-test-cache-")
