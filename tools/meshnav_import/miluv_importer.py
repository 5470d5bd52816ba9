"""One robot of a MILUV experiment folder -> meshnav dataset folder (docs/formats.md); with
`--robot all`, every robot of tags.yaml that has a folder -> OUT/<robot>/ and OUT/fleet.yaml for
`meshnav run --fleet` (docs/fleet.md), the vehicles named as the robots.

Layout read: DIR/anchors.yaml ({id: [x, y, z]}, Vicon world frame), DIR/tags.yaml
({robot: {tag id: [x, y, z]}}, body = PX4 IMU frame), DIR/<robot>/imu_px4.csv, uwb_range.csv,
mocap.csv, height.csv. Written: imu.csv, ranges.csv, groundtruth.csv (mocap, same frame as the
anchors), height.csv (t,range_m: downward laser range), setup.yaml, truth.yaml (align_required:
false). Time stamps are the files' `timestamp` texts, unchanged.

Ids: MILUV anchors are 0-5, and meshnav ids must be > 0 and distinct from the IMU id 1, so anchor
k becomes k + --anchor-id-offset (default 100); tag ids (10, 11, 20, ...) are kept. Ranges between
this robot's tags and another robot's tags are kept with type T on both ends.

Only the measured columns of uwb_range.csv are read (`timestamp`, `from_id`, `to_id` and the
range column); its truth columns (gt_range, bias, r_iw_a_*, q_ai_*, ...) never leave this module.
"""

import csv
import os

from . import dataset_writer as dw

IMU_ID = 1
IMU_COLS = ["timestamp", "linear_acceleration.x", "linear_acceleration.y", "linear_acceleration.z",
            "angular_velocity.x", "angular_velocity.y", "angular_velocity.z"]
MOCAP_COLS = ["timestamp", "pose.position.x", "pose.position.y", "pose.position.z", "pose.orientation.x",
              "pose.orientation.y", "pose.orientation.z", "pose.orientation.w"]
HEIGHT_COLS = ["timestamp", "range"]


def add_arguments(p):
    p.add_argument("--dir", required=True, help="experiment folder (anchors.yaml, tags.yaml, <robot>/)")
    p.add_argument("--robot", required=True,
                   help="robot folder name, e.g. ifo001; 'all': every robot of tags.yaml with a folder, each to "
                        "OUT/<robot>, and OUT/fleet.yaml")
    p.add_argument("--out", required=True, help="dataset folder to write (created); with --robot all, the fleet folder")
    p.add_argument("--anchor-id-offset", type=int, default=100, help="meshnav anchor id = MILUV id + this (default 100)")
    p.add_argument("--range-column", default="range", choices=("range", "range_raw"),
                   help="measured range column of uwb_range.csv (default range: MILUV's processed range)")


def _load_yaml(path):
    import yaml
    try:
        with open(path, encoding="utf-8") as f:
            data = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as ex:
        raise ValueError(f"{path}: cannot read ({ex})")
    if not isinstance(data, dict):
        raise ValueError(f"{path}: top level must be a map")
    return data


def _vec3(v, path, key):
    try:
        out = tuple(float(x) for x in v)
    except (TypeError, ValueError):
        out = ()
    if len(out) != 3 or not dw.finite(*out):
        raise ValueError(f"{path}: {key} must be a list of 3 numbers [m]")
    return out


def _rows(path, needed, report):
    """Yields (line number, [floats of `needed`], [texts of `needed`]); bad rows are counted."""
    name = os.path.basename(path)
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        missing = [c for c in needed if c not in (reader.fieldnames or [])]
        if missing:
            raise ValueError(f"{path}: missing columns {', '.join(missing)}")
        for line, row in enumerate(reader, start=2):
            texts = [(row.get(c) or "").strip() for c in needed]
            try:
                vals = [float(x) for x in texts]
            except ValueError:
                vals = None
            if vals is None or not dw.finite(*vals):
                report.bad(f"{name}:bad_value", f"{path}:{line}", "a needed value is missing or not finite; row skipped")
                continue
            yield line, vals, texts


def _imu(path, report):
    return [dw.imu_row(tx[0], v[1:4], v[4:7]) for _, v, tx in _rows(path, IMU_COLS, report)]


def _mocap(path, report):
    out = []
    for line, v, tx in _rows(path, MOCAP_COLS, report):
        if not dw.quaternion_ok(v[4:8]):
            report.bad("mocap.csv:bad_quaternion", f"{path}:{line}", "quaternion norm far from 1; row skipped")
            continue
        out.append(dw.tum_row(tx[0], v[1:4], v[4:8]))
    return out


def _height(path, report):
    return [[tx[0], dw.num(v[1])] for _, v, tx in _rows(path, HEIGHT_COLS, report)]


def _classify(a, b, own_tags, all_tags, anchor_ids):
    """Which kind of range (a initiator, b responder) this is for the robot, or None to drop."""
    if a not in own_tags and b not in own_tags:
        return None
    other = b if a in own_tags else a
    if other in anchor_ids:
        return "anchor"
    if other in all_tags and other not in own_tags:
        return "inter_robot"
    return None


def _ranges(path, col, own_tags, all_tags, anchor_ids, offset, report):
    """ranges.csv rows of the robot's tags: tag-anchor (T, A) and inter-robot (T, T)."""
    out = []
    for line, v, tx in _rows(path, ["timestamp", col, "from_id", "to_id"], report):
        where = f"{path}:{line}"
        if v[2] != int(v[2]) or v[3] != int(v[3]):
            report.bad("uwb_range.csv:bad_id", where, "ids are not integers; row skipped")
            continue
        a, b = int(v[2]), int(v[3])
        kind = _classify(a, b, own_tags, all_tags, anchor_ids)
        if kind is None:
            report.bad("uwb_range.csv:not_this_robot", where, f"range {a}-{b} involves none of this robot's tags "
                       "with a known partner; row skipped")
            continue
        if not dw.MIN_RANGE_M <= v[1] <= dw.MAX_RANGE_M:
            report.bad("uwb_range.csv:bad_range", where, f"range {v[1]} m is not plausible; row skipped")
            continue
        report.count(f"ranges:{kind}")
        ids = [x + offset if x in anchor_ids else x for x in (a, b)]
        types = ["A" if x in anchor_ids else "T" for x in (a, b)]
        out.append(dw.range_row(tx[0], v[1], ids[0], ids[1], types[0], types[1]))
    return out


def _setup_ids(args):
    anchors_path = os.path.join(args.dir, "anchors.yaml")
    tags_path = os.path.join(args.dir, "tags.yaml")
    raw_anchors = _load_yaml(anchors_path)
    anchors = {int(k): _vec3(v, anchors_path, str(k)) for k, v in raw_anchors.items()}
    tags_by_robot = _load_yaml(tags_path)
    if args.robot not in tags_by_robot:
        raise ValueError(f"{tags_path}: no tags for robot '{args.robot}' (has {', '.join(map(str, tags_by_robot))})")
    own = {int(k): _vec3(v, tags_path, f"{args.robot}.{k}") for k, v in tags_by_robot[args.robot].items()}
    all_tags = {int(k) for r in tags_by_robot.values() for k in r}
    mapped = {k + args.anchor_id_offset for k in anchors}
    clash = mapped & (all_tags | {IMU_ID}) or {k for k in mapped if k <= 0}
    if clash:
        raise ValueError(f"--anchor-id-offset {args.anchor_id_offset}: anchor ids {sorted(clash)} clash with "
                         "tags or the IMU id, or are not > 0")
    return anchors, own, all_tags


ROBOT_NAME_CHARS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-")


def _robots_with_folders(args):
    """The robots of tags.yaml with a folder in --dir, in tags.yaml's order; the others are logged."""
    tags_path = os.path.join(args.dir, "tags.yaml")
    robots = []
    for r in map(str, _load_yaml(tags_path)):
        if not os.path.isdir(os.path.join(args.dir, r)):
            dw.log(f"robot {r}: in {tags_path} but no folder {os.path.join(args.dir, r)}: skipped")
        elif not (1 <= len(r) <= 64 and set(r) <= ROBOT_NAME_CHARS):
            raise ValueError(f"{tags_path}: robot '{r}' is not a fleet vehicle name (1-64 of [A-Za-z0-9_-])")
        else:
            robots.append(r)
    if not robots:
        raise ValueError(f"{args.dir}: no robot of {tags_path} has a folder")
    return robots


def run(args):
    """Imports one robot, or every robot (`--robot all`); returns the process exit code."""
    if args.robot != "all":
        return _run_robot(args)
    import argparse
    robots = _robots_with_folders(args)
    out = dw.prepare_out_dir(args.out)
    for r in robots:
        dw.log(f"robot {r} -> {os.path.join(out, r)}")
        code = _run_robot(argparse.Namespace(**{**vars(args), "robot": r, "out": os.path.join(out, r)}))
        if code != 0:
            return code
    lines = ["# written by ./meshnav import miluv --robot all: one vehicle per robot, for meshnav run --fleet",
             "# (docs/fleet.md); the inter-robot ranges are in each robot's ranges.csv (type T on both ends)",
             "vehicles:"] + [f"  - {{name: {r}, dataset: {r}}}" for r in robots]
    with open(os.path.join(out, "fleet.yaml"), "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    dw.log(f"wrote {os.path.join(out, 'fleet.yaml')}: {len(robots)} vehicles ({', '.join(robots)})")
    return 0


def _run_robot(args):
    """Imports one robot; returns the process exit code."""
    report = dw.Report()
    anchors, own, all_tags = _setup_ids(args)
    rdir = os.path.join(args.dir, args.robot)
    if not os.path.isdir(rdir):
        raise ValueError(f"{rdir}: robot folder does not exist")
    path = lambda name: os.path.join(rdir, name)  # noqa: E731
    ranges = _ranges(path("uwb_range.csv"), args.range_column, set(own), all_tags, set(anchors),
                     args.anchor_id_offset, report)
    imu, mocap = _imu(path("imu_px4.csv"), report), _mocap(path("mocap.csv"), report)
    height = _height(path("height.csv"), report) if os.path.exists(path("height.csv")) else []
    off = args.anchor_id_offset
    mapped = {k + off: p for k, p in anchors.items()}
    out = dw.prepare_out_dir(args.out)
    dw.write_csv(os.path.join(out, "imu.csv"), dw.IMU_HEADER, dw.sort_by_time(imu, report, "imu.csv"))
    dw.write_csv(os.path.join(out, "ranges.csv"), dw.RANGES_HEADER, dw.sort_by_time(ranges, report, "ranges.csv"))
    dw.write_csv(os.path.join(out, "groundtruth.csv"), dw.TUM_HEADER, dw.sort_by_time(mocap, report, "groundtruth.csv"))
    if height:
        dw.write_csv(os.path.join(out, "height.csv"), dw.HEIGHT_HEADER, dw.sort_by_time(height, report, "height.csv"))
    note = "no IMU noise figures: the PX4 IMU's are not published with the data; the estimator's defaults apply"
    # MILUV's `range` is its processed range, antenna delays and the received-power bias removed
    # (the file keeps `range_raw` and `bias_raw` beside it): the pairs are calibrated, so their
    # constant biases are not states (docs/uwb_bias_model.md). `range_raw` keeps the default model.
    noise = {"sigma_gamma": 0.0} if args.range_column == "range" else None
    if noise:
        note += "; noise.sigma_gamma 0: column 'range' is calibrated (antenna delays and power bias removed by MILUV)"
    dw.write_setup_yaml(os.path.join(out, "setup.yaml"), own, mapped, IMU_ID, noise, comments=(
        f"imported from MILUV {os.path.basename(os.path.normpath(args.dir))}/{args.robot} by ./meshnav import miluv",
        f"anchor ids = MILUV anchor id + {off}; tag ids as in MILUV; ranges column '{args.range_column}'", note))
    dw.write_truth_yaml(os.path.join(out, "truth.yaml"), mapped, "vicon world (the anchors' frame)", False, comments=(
        f"groundtruth.csv: {args.robot}/mocap.csv, body (PX4 IMU) frame in the Vicon world frame",))
    dw.log(f"wrote {out}: imu.csv {len(imu)} rows, ranges.csv {len(ranges)} rows "
           f"({report.counts['ranges:anchor']} tag-anchor, {report.counts['ranges:inter_robot']} inter-robot), "
           f"groundtruth.csv {len(mocap)} rows, height.csv {len(height)} rows")
    dw.log(f"counters: {report.summary()}")
    return 0
