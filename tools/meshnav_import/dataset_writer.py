"""Helpers shared by every importer: counters of dropped input, progress, and writers of the
dataset files of docs/formats.md (imu.csv, ranges.csv, groundtruth.csv, height.csv, setup.yaml,
truth.yaml).

Time stamps are passed around as *text* (e.g. "1664959676.989318950") so that the recording's own
time stamps reach the files digit for digit; numbers are written with repr() (shortest text that
reads back to the same double).
"""

import math
import os
import sys
import time
from collections import Counter

IMU_HEADER = "t,lin_acc_x,lin_acc_y,lin_acc_z,ang_vel_x,ang_vel_y,ang_vel_z"
RANGES_HEADER = "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS"
TUM_HEADER = "#t,tx,ty,tz,qx,qy,qz,qw"
HEIGHT_HEADER = "t,range_m"

#: Ranges outside [MIN_RANGE_M, MAX_RANGE_M] are absurd (the limits of common/dataset.h).
MIN_RANGE_M = -0.5
MAX_RANGE_M = 500.0


def log(msg):
    """One line on stderr, prefixed like the C++ tools' logs."""
    print(f"[meshnav import] {msg}", file=sys.stderr, flush=True)


class Report:
    """Counts dropped or repaired input by key and prints the first few messages of each key
    (the location of the bad input: file and line, or topic and message index)."""

    def __init__(self, max_messages_per_key=5):
        self.counts = Counter()
        self.max_messages = max_messages_per_key

    def bad(self, key, where, what):
        self.counts[key] += 1
        if self.counts[key] <= self.max_messages:
            log(f"{where}: {what}")
        elif self.counts[key] == self.max_messages + 1:
            log(f"... further '{key}' messages are only counted")

    def count(self, key, n=1):
        self.counts[key] += n

    def summary(self):
        return ", ".join(f"{k}={v}" for k, v in sorted(self.counts.items())) or "none"


class Progress:
    """Logs 'what: 40 % (n/total)' at most every `period_s` seconds."""

    def __init__(self, what, total, period_s=2.0):
        self.what, self.total, self.period = what, max(int(total), 1), period_s
        self.last = time.monotonic()

    def update(self, n):
        now = time.monotonic()
        if now - self.last >= self.period:
            self.last = now
            log(f"{self.what}: {100.0 * n / self.total:.0f} % ({n}/{self.total})")


def num(x):
    """Shortest exact text of a float."""
    return repr(float(x))


def finite(*xs):
    return all(isinstance(x, (int, float)) and math.isfinite(x) for x in xs)


def stamp_text(secs, nsecs):
    """ROS time (secs, nsecs) as decimal seconds with all nine digits."""
    return f"{int(secs)}.{int(nsecs):09d}"


def sort_by_time(rows, report, name):
    """Sorts rows (first element: time text) by time, stable; counts rows that were out of order."""
    backwards = sum(1 for a, b in zip(rows, rows[1:]) if float(b[0]) < float(a[0]))
    if backwards:
        report.count(f"{name}:time_backwards_sorted", backwards)
        log(f"{name}: {backwards} samples earlier than their predecessor; rows sorted by time")
        rows.sort(key=lambda r: float(r[0]))
    return rows


def write_csv(path, header, rows):
    """Writes rows (sequences of already formatted text) under `header`."""
    with open(path, "w", encoding="utf-8") as f:
        f.write(header + "\n")
        for r in rows:
            f.write(",".join(r) + "\n")


def imu_row(t_text, acc, gyro):
    return [t_text] + [num(v) for v in acc] + [num(v) for v in gyro]


def range_row(t_text, range_m, id1, id2, type1, type2):
    """ranges.csv row. R is written as 0 (unknown): the estimator then uses its own σ."""
    return [t_text, num(range_m), num(range_m), "0", str(id1), str(id2), type1, type2, "1"]


def tum_row(t_text, p, q_xyzw):
    return [t_text] + [num(v) for v in p] + [num(v) for v in q_xyzw]


def quaternion_ok(q_xyzw, tol=0.1):
    return finite(*q_xyzw) and abs(math.sqrt(sum(v * v for v in q_xyzw)) - 1.0) <= tol


def _vec(v):
    return "[" + ", ".join(num(x) for x in v) + "]"


def write_setup_yaml(path, tags, anchors, imu_id=1, noise=None, comments=()):
    """setup.yaml (docs/formats.md) without baro and pair_biases: `tags` {id: p_TinI}, `anchors`
    {id: p_AinG}, `noise` {key: value} (only the keys given), `comments` lines at the top."""
    lines = [f"# {c}" for c in comments]
    lines.append(f"imu_id: {int(imu_id)}")
    lines.append("rel_tag_positions:  # tag position in the IMU frame [m]")
    lines += [f"  {int(i)}: {_vec(p)}" for i, p in sorted(tags.items())]
    lines.append("abs_anchor_positions:  # known anchors in the world frame G [m]")
    lines += [f"  {int(i)}: {_vec(p)}" for i, p in sorted(anchors.items())]
    if noise:
        lines.append("noise:")
        lines += [f"  {k}: {num(v)}" for k, v in noise.items()]
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")


def write_truth_yaml(path, anchors, truth_frame, align_required, comments=()):
    """truth.yaml: anchors as known to the recording (frame G), the frame of groundtruth.csv and
    whether evaluation must align the estimate to it."""
    lines = ["# evaluation only, never read by estimator or calibrator"]
    lines += [f"# {c}" for c in comments]
    lines.append("anchor_positions:  # anchors in the world frame G [m]")
    lines += [f"  {int(i)}: {_vec(p)}" for i, p in sorted(anchors.items())]
    lines.append(f"truth_frame: \"{truth_frame}\"  # frame of groundtruth.csv")
    lines.append(f"align_required: {'true' if align_required else 'false'}")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")


def prepare_out_dir(out_dir):
    os.makedirs(out_dir, exist_ok=True)
    return out_dir
