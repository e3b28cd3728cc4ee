"""vbcl_stats.py — running vbcl for its statistics, shared by the scripts that measure it
(bench.py, bench_aa.py, gallery.py); no modules beyond Python's own."""
import json
import os
import subprocess
import sys
import tempfile


def read_stats_json(vbcl, scene, opts, env=None):
    """Runs vbcl -q --stats-json on scene; returns the document (fields: docs/stats.md).
    A failed run prints vbcl's own message before the exception."""
    fd, path = tempfile.mkstemp(prefix="vbcl-stats-", suffix=".json")
    os.close(fd)
    try:
        r = subprocess.run([vbcl, scene, "-q", "--stats-json", path] + list(opts),
                           capture_output=True, text=True, env=env)
        if r.returncode != 0:
            sys.stderr.write(r.stderr)
            r.check_returncode()
        with open(path) as f:
            return json.load(f)
    finally:
        os.remove(path)
