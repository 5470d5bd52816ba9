#!/usr/bin/env python3
"""The logger's flush policy over LCM with the real processes (issue 12, item 4; docs/faults.md).

    logger_restart_test.py BIN_DIR WORK_DIR [FLUSH_PERIOD_S]

Run it through scripts/lcm_netns.sh (a private network namespace with multicast on its loopback,
or the documented fallback on the host). Steps, each wait on a condition with a bound:

 1. `logging --run-id 42 --flush-period P --lcmlog` is started; once it has subscribed,
    meshnav_publish_sequence sends ANCHOR_INIT 101 and 102, then POSE 0..799 at 100 Hz with an
    ANCHORS (anchors 201, 202) after every 10th POSE.
 2. Once estimate.csv holds 300 rows, 0.8 P after it next grows, the logger is killed (-9)
    while the publisher goes on.
    Checked on the files it left: every POSE / ANCHORS sent more than P + SLACK before the kill
    is in estimate.csv, anchors.csv and the lcmlog; what is missing is only the newest rows (no
    gap); anchor_init.yaml has 101 and 102.
 3. The logger is restarted with the same run id, the publisher sends ANCHOR_INIT 103 and
    POSE 800..999; the last one must be in estimate.csv within P + SLACK of its sending (the
    periodic flush); the logger is stopped with SIGTERM (exit 0).
 4. Checked: one header per CSV, every line whole, rows in time order, the rows of the first
    incarnation kept as they were, every row of the second there; the lcmlog reads back to its end
    (the second incarnation's events after the first's, in time order); anchor_init.yaml has 101,
    102, 103 once each; summary.yaml counts the second incarnation's 200 POSE.

Prints the measured figures (rows before the kill, rows lost, the oldest lost row's age against
the bound) and PASS, or FAIL: with the reason.
"""
import os
import shutil
import signal
import subprocess
import sys
import time

import yaml

BIN = os.path.abspath(sys.argv[1])
WORK = os.path.abspath(sys.argv[2])
P = float(sys.argv[3]) if len(sys.argv) > 3 else 0.5
# 100 Hz: less than a CSV writer's buffer (8 KiB) per flush period, so the CSV rows reach the file
# by the periodic flush alone (the lcmlog's 4 KiB stdio buffer spills in between, mid-event).
RATE_HZ = 100.0
N1, N_KILL, N2 = 800, 300, 200  # POSE of the first incarnation, rows seen before the kill, POSE of the second
SLACK_S = 0.3  # scheduling on a busy machine: the logger's flush beat and its reception may lag
RUN = os.path.join(WORK, "run")
LCMLOG = os.path.join(RUN, "run.lcmlog")
ESTIMATE_HEADER = "t,tx,ty,tz,qx,qy,qz,qw,pxx,pxy,pxz,pyy,pyz,pzz,qrr,qrp,qry,qpp,qpy,qyy"
ANCHORS_HEADER = "t,id,x,y,z,pxx,pxy,pxz,pyy,pyz,pzz"
procs = []


def fail(msg):
    print(f"FAIL: {msg}")
    for name in sorted(os.listdir(WORK)):
        if name.endswith(".log"):
            with open(os.path.join(WORK, name)) as f:
                print(f"---- {name} (last lines)\n" + "".join(f.readlines()[-15:]))
    for p in procs:
        if p.poll() is None:
            p.kill()
    sys.exit(1)


def wait_for(cond, what, limit_s):
    start = time.monotonic()
    while not cond():
        if time.monotonic() - start > limit_s:
            fail(f"{what}: not within {limit_s} s")
        time.sleep(0.02)


def start(name, args):
    log = open(os.path.join(WORK, name + ".log"), "a")
    p = subprocess.Popen([os.path.join(BIN, args[0])] + args[1:], stdout=log, stderr=subprocess.STDOUT)
    procs.append(p)
    return p


def text(path):
    try:
        with open(path) as f:
            return f.read()
    except FileNotFoundError:
        return ""


def index_of(t):
    """POSE number of data time t (meshnav_publish_sequence: t = 100 s + i * 10 ms)."""
    return round((float(t) - 100.0) / 0.01)


def csv_rows(path, header, n_fields):
    """(rows as lists of fields, lines): fails on a second header or a line that is not whole."""
    content = text(path)
    lines = content.split("\n")
    if lines[-1] != "":
        fail(f"{path}: the last line is not whole: {lines[-1][:60]!r}")
    lines = lines[:-1]
    if not lines or lines[0] != header:
        fail(f"{path}: no header")
    rows = []
    for k, line in enumerate(lines[1:], start=2):
        f = line.split(",")
        if line == header:
            fail(f"{path}:{k}: a second header")
        if len(f) != n_fields:
            fail(f"{path}:{k}: {len(f)} fields instead of {n_fields}: {line[:80]!r}")
        try:
            [float(x) for x in f]
        except ValueError:
            fail(f"{path}:{k}: not a number: {line[:80]!r}")
        rows.append(f)
    return rows, lines


def lcmlog_events(path):
    out = subprocess.run([os.path.join(BIN, "meshnav_lcmlog_dump"), path], capture_output=True, text=True)
    if out.returncode != 0:
        fail(f"meshnav_lcmlog_dump {path}: exit {out.returncode}: {out.stderr}")
    events, total, bad = [], None, None
    for line in out.stdout.splitlines():
        f = line.split(",")
        if f[0] == "events":
            total = int(f[1])
        elif f[0] == "bad":
            bad = int(f[1])
        else:
            events.append((f[0], int(f[1]), f[2]))
    if bad:
        fail(f"{path}: {bad} events do not decode")
    return events


def sent_record(path):
    sent = {}
    for line in text(path).splitlines():
        ch, i, wall = line.split(",")
        sent[(ch, int(i))] = int(wall) * 1e-6
    return sent


def check_after_kill(t_kill, t_dead, sent, label):
    """Every POSE / ANCHORS sent more than P + SLACK before the kill (t_kill: just before the
    signal; t_dead: once the logger was gone) is in the files; only the newest are missing; none
    sent after t_dead is there. Returns the figures."""
    bound = P + SLACK_S
    est, _ = csv_rows(os.path.join(RUN, "estimate.csv"), ESTIMATE_HEADER, 20)
    anc, _ = csv_rows(os.path.join(RUN, "anchors.csv"), ANCHORS_HEADER, 11)
    events = lcmlog_events(LCMLOG)
    have = {
        "estimate.csv": {index_of(r[0]) for r in est},
        "anchors.csv": {index_of(r[0]) for r in anc},
        "lcmlog POSE": {index_of(e[2]) for e in events if e[0] == "POSE"},
        "lcmlog ANCHORS": {index_of(e[2]) for e in events if e[0] == "ANCHORS"},
    }
    channel = {"estimate.csv": "POSE", "anchors.csv": "ANCHORS", "lcmlog POSE": "POSE",
               "lcmlog ANCHORS": "ANCHORS"}
    figures = {}
    for name, got in have.items():
        before = sorted(i for (ch, i), w in sent.items() if ch == channel[name] and w < t_kill)
        lost = [i for i in before if i not in got]
        late = sorted(got - {i for (ch, i), w in sent.items() if ch == channel[name] and w < t_dead})
        if late:
            fail(f"{label} {name}: rows {late[:5]} sent after the kill")
        if lost and got and min(lost) < max(got):
            gaps = [i for i in lost if i < max(got)]
            fail(f"{label} {name}: rows {gaps[:5]} missing before the last kept row {max(got)} (a gap)")
        age = t_kill - min(sent[(channel[name], i)] for i in lost) if lost else 0.0
        if age > bound:
            fail(f"{label} {name}: lost row {lost[0]} was sent {age:.3f} s before the kill (bound {bound:.2f} s)")
        figures[name] = (len(before), len(lost), age)
        print(f"{label} {name}: {len(before)} sent before the kill, {len(got)} kept, {len(lost)} lost, "
              f"oldest lost sent {age:.3f} s before the kill (bound P + slack = {bound:.2f} s)")
    inits = yaml.safe_load(text(os.path.join(RUN, "anchor_init.yaml")) or "{}") or {}
    ids = [a["id"] for a in inits.get("anchors", [])]
    if ids != [101, 102]:
        fail(f"{label}: anchor_init.yaml has anchors {ids}, not [101, 102]")
    return figures


def main():
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    logger_args = ["logging", "--out", RUN, "--lcmlog", LCMLOG, "--run-id", "42", "--flush-period", str(P)]
    print(f"== logger with --flush-period {P} s over {os.environ.get('LCM_DEFAULT_URL', '(default LCM URL)')}")
    log1 = start("logging", logger_args)
    wait_for(lambda: "recording into" in text(os.path.join(WORK, "logging.log")), "the logger's start", 30)

    print(f"== publish POSE 0..{N1 - 1} at {RATE_HZ:.0f} Hz; kill -9 the logger 0.8 P after estimate.csv grows past {N_KILL} rows")
    pub1 = start("publish1", ["meshnav_publish_sequence", "--first", "0", "--count", str(N1), "--rate", str(RATE_HZ),
                              "--anchors-every", "10", "--anchor-inits", "101,102",
                              "--record", os.path.join(WORK, "sent1.csv")])
    est = os.path.join(RUN, "estimate.csv")
    wait_for(lambda: text(est).count("\n") > N_KILL, f"estimate.csv reaching {N_KILL} rows", 60)
    # Then the next time the file grows (a flush, or the writer's buffer spilling). The kill is
    # placed 0.8 P after it, late in a flush period (not a wait for a condition: wherever the kill
    # lands the checks hold; placed there the lcmlog's stdio buffer has spilt half an event).
    size0 = os.path.getsize(est)
    wait_for(lambda: os.path.getsize(est) != size0, "estimate.csv growing", 10)
    time.sleep(0.8 * P)
    t_kill = time.time()
    log1.send_signal(signal.SIGKILL)
    log1.wait()
    t_dead = time.time()
    # What the kill left, before anything else touches the files.
    left = {name: text(os.path.join(RUN, name)) for name in ("estimate.csv", "anchors.csv")}
    left_lcmlog_bytes = os.path.getsize(LCMLOG)
    if pub1.wait(timeout=60) != 0:
        fail("meshnav_publish_sequence (first) failed")
    sent1 = sent_record(os.path.join(WORK, "sent1.csv"))
    for name, content in left.items():
        tail = content[content.rfind("\n") + 1:]
        print(f"after kill -9: {name} {len(content)} bytes, {content.count(chr(10)) - 1} whole rows"
              + (f", a torn last row of {len(tail)} bytes" if tail else ", no torn row"))
    print(f"after kill -9: run.lcmlog {left_lcmlog_bytes} bytes")

    print(f"== restart the logger with the same run id; publish POSE {N1}..{N1 + N2 - 1}; SIGTERM")
    log2 = start("logging", logger_args)
    wait_for(lambda: text(os.path.join(WORK, "logging.log")).count("recording into") >= 2, "the restart", 30)
    if "continuing the files" not in text(os.path.join(WORK, "logging.log")):
        fail("the restarted logger did not continue its files")
    figures = check_after_kill(t_kill, t_dead, sent1, "first incarnation")
    pub2 = start("publish2", ["meshnav_publish_sequence", "--first", str(N1), "--count", str(N2), "--rate",
                              str(RATE_HZ), "--anchors-every", "10", "--anchor-inits", "103",
                              "--record", os.path.join(WORK, "sent2.csv")])
    if pub2.wait(timeout=60) != 0:
        fail("meshnav_publish_sequence (second) failed")
    last = N1 + N2 - 1
    wait_for(lambda: text(est).endswith("\n") and index_of(text(est).rstrip("\n").rsplit("\n", 1)[-1].split(",")[0])
             == last, f"estimate.csv showing POSE {last}", 30)
    visible_after = time.time() - sent_record(os.path.join(WORK, "sent2.csv"))[("POSE", last)]
    print(f"the last POSE was in estimate.csv {visible_after:.3f} s after it was sent (periodic flush; bound "
          f"{P + SLACK_S:.2f} s)")
    if visible_after > P + SLACK_S:
        fail(f"the last POSE reached estimate.csv {visible_after:.3f} s after it was sent (bound {P + SLACK_S:.2f} s)")
    log2.send_signal(signal.SIGTERM)
    if log2.wait(timeout=30) != 0:
        fail(f"the logger exited with {log2.returncode} on SIGTERM")

    print("== the files of both incarnations")
    sent2 = sent_record(os.path.join(WORK, "sent2.csv"))
    for name, header, n_fields, ch in (("estimate.csv", ESTIMATE_HEADER, 20, "POSE"),
                                       ("anchors.csv", ANCHORS_HEADER, 11, "ANCHORS")):
        rows, lines = csv_rows(os.path.join(RUN, name), header, n_fields)
        kept = left[name][: left[name].rfind("\n") + 1]
        if not text(os.path.join(RUN, name)).startswith(kept):
            fail(f"{name}: the rows the first incarnation wrote are not kept as they were")
        times = [float(r[0]) for r in rows]
        if any(b < a for a, b in zip(times, times[1:])):
            fail(f"{name}: rows not in time order")
        got = {index_of(r[0]) for r in rows}
        second = {i for (c, i) in sent2 if c == ch}
        if not second <= got:
            fail(f"{name}: rows of the second incarnation missing: {sorted(second - got)[:5]}")
        print(f"{name}: 1 header, {len(rows)} rows in time order, {len(kept.splitlines()) - 1} from the first "
              f"incarnation kept, all {len(second)} of the second")
    events = lcmlog_events(LCMLOG)
    poses = [e for e in events if e[0] == "POSE"]
    second = {i for (c, i) in sent2 if c == "POSE"}
    got = {index_of(e[2]) for e in poses}
    if not second <= got:
        fail(f"run.lcmlog: POSE of the second incarnation missing: {sorted(second - got)[:5]}")
    recv = [e[1] for e in events]
    if any(b < a for a, b in zip(recv, recv[1:])):
        fail("run.lcmlog: events not in time order")
    inits = [e for e in events if e[0] == "ANCHOR_INIT"]
    if len(inits) != 3:
        fail(f"run.lcmlog: {len(inits)} ANCHOR_INIT events, not 3")
    print(f"run.lcmlog: {len(events)} events read back in time order, {len(poses)} POSE, {len(inits)} ANCHOR_INIT")
    ids = [a["id"] for a in (yaml.safe_load(text(os.path.join(RUN, "anchor_init.yaml"))) or {}).get("anchors", [])]
    if ids != [101, 102, 103]:
        fail(f"anchor_init.yaml has anchors {ids}, not [101, 102, 103]")
    summary = yaml.safe_load(text(os.path.join(RUN, "summary.yaml")) or "null")
    if not summary:
        fail("no summary.yaml")
    if summary["channels"]["POSE"]["messages"] != N2 or summary["files"]["estimate_rows"] != N2:
        fail(f"summary.yaml: {summary['channels']['POSE']} / {summary['files']}, not the second incarnation's {N2} POSE")
    counters = summary.get("logger_counters") or {}
    for name, content in left.items():
        torn = not content.endswith("\n")
        if counters.get(f"{name}:torn_row_cut", 0) != int(torn):
            fail(f"summary.yaml: {name}:torn_row_cut is {counters.get(f'{name}:torn_row_cut', 0)}, the kill left "
                 f"{'a' if torn else 'no'} torn row")
    print(f"anchor_init.yaml: 101, 102, 103; summary.yaml: the second incarnation's {N2} POSE; torn ends cut on "
          f"the restart: {', '.join(f'{k}={v}' for k, v in counters.items() if 'torn' in k) or 'none'}")
    n, lost, age = figures["estimate.csv"]
    print(f"figures: flush period {P} s, {n} POSE sent before the kill, {lost} rows lost, oldest lost sent "
          f"{age:.3f} s before the kill (bound {P + SLACK_S:.2f} s)")
    print("PASS")


if __name__ == "__main__":
    try:
        main()
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
