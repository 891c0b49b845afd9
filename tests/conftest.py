"""Test session set-up: the timeline cache lives in a folder of this session (a run never reads timelines
that another run, or another version of the code, wrote)."""

import os
import tempfile

if "LVGYM_CACHE_DIR" not in os.environ:
    os.environ["LVGYM_CACHE_DIR"] = tempfile.mkdtemp(prefix="lvgym-test-cache-")
# the ledger of test flights (lvgym.benchmark.ledger): a file of this session, never the committed one
os.environ["LVGYM_TEST_FLIGHTS"] = os.path.join(tempfile.mkdtemp(prefix="lvgym-test-ledger-"), "test-flights.jsonl")
