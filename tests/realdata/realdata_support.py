"""Shared by the real-data tests: where the repository, the shared recordings and the binaries
are, how to run an importer, and the skip rule (shared data missing: skip with the reason; the
environment variable CI set: fail instead)."""

import csv
import os
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.abspath(os.environ.get("MESHNAV_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")))
SHARED = os.path.abspath(os.path.join(REPO, "..", "shared"))
TOOLS = os.path.join(REPO, "tools")
BIN = os.environ.get("MESHNAV_BIN_DIR", os.path.join(REPO, "build", "bin"))
ISAS_BAG = os.path.join(SHARED, "data", "real-isas-walk1", "ISAS-Walk1.bag")
MILUV_DIR = os.path.join(SHARED, "data", "real-miluv-3drones")

sys.path.insert(0, TOOLS)


def require(path):
    """Skips the test when `path` (shared data) is missing, or fails when CI is set."""
    if os.path.exists(path):
        return
    reason = f"shared data not present: {path} (expected at ../shared beside the repository)"
    if os.environ.get("CI"):
        raise AssertionError(reason + "; CI is set, so this is a failure, not a skip")
    raise unittest.SkipTest(reason)


def run_import(*args):
    """Runs `python3 -m meshnav_import ARGS` as ./meshnav import does; returns (code, stderr)."""
    env = dict(os.environ, PYTHONPATH=TOOLS, PYTHONDONTWRITEBYTECODE="1")
    p = subprocess.run([sys.executable, "-m", "meshnav_import", *args], env=env, capture_output=True, text=True,
                       timeout=300)
    return p.returncode, p.stderr


def counters(stderr):
    """The 'counters: a=1, b=2' line of an import log as a dict."""
    line = [l for l in stderr.splitlines() if "counters:" in l][-1]
    text = line.split("counters:", 1)[1].strip()
    return {} if text == "none" else {k: int(v) for k, v in (kv.split("=") for kv in text.split(", "))}


def read_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def read_text(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def read_yaml(path):
    import yaml
    return yaml.safe_load(read_text(path))


def import_to_temp(name, *args):
    """Imports into a new temporary folder: returns (TemporaryDirectory, dataset dir, code, log);
    the caller cleans the folder up."""
    tmp = tempfile.TemporaryDirectory()
    out = os.path.join(tmp.name, name)
    code, log = run_import(*args, "--out", out)
    return tmp, out, code, log
