#!/usr/bin/env python3
"""The comparison at the end of `./meshnav demo --real` (scripts/demo_real.sh): position ATE of the
LCM run, of the in-process run (meshnav_run) and of plain multilateration of the same ranges, from
the two metrics.yaml files meshnav_eval wrote (the baseline is the same dataset's, so either has it).

Usage: demo_compare.py LCM_METRICS_YAML RUN_METRICS_YAML

Exit 0 with the table on stdout. Exit 1 with one message on stderr, no traceback, when a file is
missing or not a metrics file, or a run has no pose metrics: meshnav_eval writes `pose: null` when
no estimate could be evaluated, e.g. when the estimator never initialized.
"""
import math
import sys

import yaml


class ComparisonError(Exception):
    """What makes the comparison impossible, said for the user."""


def load(path):
    try:
        with open(path) as f:
            m = yaml.safe_load(f)
    except OSError as e:
        raise ComparisonError("cannot read %s: %s" % (path, e.strerror or e))
    except yaml.YAMLError as e:
        raise ComparisonError("%s is not valid YAML: %s" % (path, str(e).splitlines()[0]))
    if not isinstance(m, dict):
        raise ComparisonError("%s is not a meshnav_eval metrics file (no mapping at the top)" % path)
    return m


def position_rmse(m, path, what):
    """(RMSE [m], number of evaluated estimates) of a run's pose metrics."""
    pose = m.get("pose")
    if not isinstance(pose, dict):
        raise ComparisonError(
            "no pose metrics for %s in %s (pose: %s): no estimate could be evaluated against the truth; "
            "did the estimator initialize? (its log says why not)" % (what, path, "null" if pose is None else pose))
    try:
        return float(pose["position"]["rmse_m"]), int(pose["n_evaluated"])
    except (KeyError, TypeError, ValueError):
        raise ComparisonError("%s: pose metrics of %s without position.rmse_m / n_evaluated" % (path, what))


def summary(lcm, run, lcm_path="LCM metrics", run_path="in-process metrics"):
    """The comparison table as text; raises ComparisonError when it cannot be made."""
    lcm_rmse, lcm_n = position_rmse(lcm, lcm_path, "the LCM run (estimator process)")
    run_rmse, run_n = position_rmse(run, run_path, "the in-process run (meshnav_run)")
    b = lcm.get("baseline") or {}
    mode = (lcm.get("alignment") or {}).get("mode", "?")
    rows = [("meshnav over LCM (estimator process)", lcm_rmse, lcm_n, "estimates"),
            ("meshnav in one process (meshnav_run)", run_rmse, run_n, "estimates"),
            ("plain multilateration of the ranges", float(b.get("position_rmse_m", math.nan)),
             int(b.get("n_evaluated", 0)), "fixes")]
    lines = ["", "ISAS-Walk1: position ATE (RMSE) after %s alignment to the Vive truth" % mode]
    lines += ["  %-38s %6.3f m   (%d %s)" % row for row in rows]
    lines.append("  LCM minus in-process: %+.3f m" % (lcm_rmse - run_rmse))
    return "\n".join(lines)


def main(argv):
    if len(argv) != 3:
        print("usage: demo_compare.py LCM_METRICS_YAML RUN_METRICS_YAML", file=sys.stderr)
        return 2
    try:
        print(summary(load(argv[1]), load(argv[2]), argv[1], argv[2]))
    except ComparisonError as e:
        print("demo --real: no comparison: %s" % e, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
