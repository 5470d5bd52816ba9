"""ROS 1 bag (e.g. ISAS-Walk1.bag) -> meshnav dataset folder (docs/formats.md).

Reads the bag with Debian's python3-rosbag (the bag embeds its message definitions, so no ROS
installation and no message packages are needed). Topics are found by message type unless given:

  IMU     sensor_msgs/Imu                      -> imu.csv
  UWB     fraunhofer_rtls_flare/RTLSStick      -> ranges.csv (fresh ranges ra = 1 only)
  anchors fraunhofer_rtls_flare/Anchorlist     -> setup.yaml abs_anchor_positions
  truth   geometry_msgs/TransformStamped, geometry_msgs/PoseStamped, nav_msgs/Odometry
                                               -> groundtruth.csv (TUM, in the truth's own frame)

Truth topic rules (without --truth-topic): among topics of a pose type, a name containing "rtls"
or "uwb" is the ranging system's own fix and never truth; a name containing one of TRUTH_WORDS
(vive, vicon, mocap, ...) is preferred; among equals the topic with the most messages wins.
Time stamps are the messages' header stamps (seconds with all nine decimals), never shifted.
"""

import math
import os

from . import dataset_writer as dw

IMU_TYPE = "sensor_msgs/Imu"
UWB_TYPES = ("fraunhofer_rtls_flare/RTLSStick",)
ANCHOR_TYPES = ("fraunhofer_rtls_flare/Anchorlist",)
POSE_TYPES = ("geometry_msgs/TransformStamped", "geometry_msgs/PoseStamped", "nav_msgs/Odometry")
TRUTH_WORDS = ("vive", "vicon", "mocap", "optitrack", "qualisys", "ground_truth", "groundtruth", "truth")
NOT_TRUTH_WORDS = ("rtls", "uwb")

#: Tag in the IMU frame [m], from the ISAS-Walk1 README (the dataset authors' configuration).
ISAS_TAG_LEVER_ARM_M = (0.1, -0.025, 0.0)
#: TDK ICM-20948 (the IMU of the Waveshare Sense HAT (B) in the ISAS rig), datasheet typical
#: noise spectral densities: accelerometer 230 µg/√Hz, gyroscope 0.015 °/s/√Hz.
ICM20948_DATASHEET = {
    "imu_acc_noise_density": 230e-6 * 9.80665,
    "imu_gyro_noise_density": math.radians(0.015),
}
#: A datasheet density is the sensor at rest on a bench. In motion, scale-factor, misalignment,
#: vibration and sampling errors add to it; the usual practice for a filter is to state about ten
#: times the datasheet (or Allan-variance) white noise. The estimator scales further when the range
#: innovations show more (process_noise.*, docs/robustness.md). ISAS-Walk1 at rest: 2.7e-3
#: m/s²/√Hz and 1.0e-3 rad/s/√Hz measured, in motion about 30× the datasheet needed.
IN_USE_FACTOR = 10.0
ICM20948_NOISE = {k: IN_USE_FACTOR * v for k, v in ICM20948_DATASHEET.items()}
DEFAULT_TAG_ID = 1000
IMU_ID = 1


def add_arguments(p):
    p.add_argument("--bag", required=True, help="ROS 1 bag file")
    p.add_argument("--out", required=True, help="dataset folder to write (created)")
    p.add_argument("--imu-topic", help=f"topic of type {IMU_TYPE} (default: found by type)")
    p.add_argument("--uwb-topic", help=f"topic of type {UWB_TYPES[0]} (default: found by type)")
    p.add_argument("--anchors-topic", help=f"topic of type {ANCHOR_TYPES[0]} (default: found by type)")
    p.add_argument("--truth-topic", help="pose topic used as ground truth (default: rules above)")
    p.add_argument("--tag-lever-arm", help="tag position in the IMU frame X,Y,Z [m] "
                   f"(default: ISAS-Walk1's {list(ISAS_TAG_LEVER_ARM_M)})")
    p.add_argument("--tag-id", type=int, default=DEFAULT_TAG_ID, help=f"id of the tag (default {DEFAULT_TAG_ID})")
    p.add_argument("--truth-in-anchor-frame", action="store_true",
                   help="the truth is in the anchors' frame (truth.yaml: align_required false)")


def _pick(topics, types, given, role, report):
    """The topic for `role`: `given` (must exist with one of `types`) or the one of those types
    with the most messages."""
    if given:
        if given not in topics:
            raise ValueError(f"--{role}-topic {given}: no such topic in the bag")
        if topics[given][0] not in types:
            raise ValueError(f"--{role}-topic {given} has type {topics[given][0]}, expected one of {', '.join(types)}")
        return given
    cands = sorted((n for n, (ty, _) in topics.items() if ty in types), key=lambda n: -topics[n][1])
    if len(cands) > 1:
        dw.log(f"{role}: several topics of type {'/'.join(types)}: {', '.join(cands)}; using {cands[0]} "
               f"(most messages; choose with --{role}-topic)")
    return cands[0] if cands else None


def choose_truth_topic(topics, given):
    """Truth topic by the rules of the module doc; returns (topic or None, reason)."""
    if given:
        return _pick(topics, POSE_TYPES, given, "truth", None), "given by --truth-topic"
    poses = [n for n, (ty, _) in topics.items() if ty in POSE_TYPES]
    allowed = [n for n in poses if not any(w in n.lower() for w in NOT_TRUTH_WORDS)]
    preferred = [n for n in allowed if any(w in n.lower() for w in TRUTH_WORDS)]
    for group, why in ((preferred, "name names a truth system"), (allowed, "only pose topic not from the ranging system")):
        if group:
            best = max(group, key=lambda n: topics[n][1])
            return best, why + (f" (of {len(group)}; most messages)" if len(group) > 1 else "")
    return None, "no pose topic other than the ranging system's own fix (" + (", ".join(poses) or "none") + ")"


def _parse_lever_arm(text):
    if text is None:
        dw.log(f"tag lever arm {list(ISAS_TAG_LEVER_ARM_M)} m: default, from the ISAS-Walk1 README (dataset authors' "
               "configuration); give --tag-lever-arm X,Y,Z for another rig")
        return ISAS_TAG_LEVER_ARM_M, "ISAS-Walk1 README default"
    parts = text.split(",")
    try:
        v = tuple(float(x) for x in parts)
    except ValueError:
        v = ()
    if len(v) != 3 or not dw.finite(*v):
        raise ValueError(f"--tag-lever-arm '{text}': expected three numbers X,Y,Z [m]")
    dw.log(f"tag lever arm {list(v)} m: given by --tag-lever-arm")
    return v, "given by --tag-lever-arm"


def _stamp(msg, bag_time, where, report):
    """Header stamp text; falls back to the bag's record time (counted) when the stamp is zero."""
    st = msg.header.stamp
    if st.secs == 0 and st.nsecs == 0:
        report.bad("stamp_from_bag_time", where, "header stamp is zero; the bag's record time is used")
        return dw.stamp_text(bag_time.secs, bag_time.nsecs)
    return dw.stamp_text(st.secs, st.nsecs)


def _pose_of(msg, ty):
    """(position xyz, quaternion xyzw) of a pose message of one of POSE_TYPES."""
    if ty == "geometry_msgs/TransformStamped":
        p, q = msg.transform.translation, msg.transform.rotation
    elif ty == "geometry_msgs/PoseStamped":
        p, q = msg.pose.position, msg.pose.orientation
    else:
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
    return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)


class _Collector:
    """What the messages of the chosen topics turn into, plus counters."""

    def __init__(self, roles, types, tag_id, report):
        self.roles, self.types, self.tag_id, self.report = roles, types, tag_id, report
        self.imu, self.ranges, self.truth = [], [], []
        self.anchors, self.anchors_from_ranges = {}, {}
        self.stick_ids = {}
        self.truth_frames = set()
        self.imu_frame = ""

    def imu_msg(self, msg, where, bag_time):
        a, w = msg.linear_acceleration, msg.angular_velocity
        acc, gyro = (a.x, a.y, a.z), (w.x, w.y, w.z)
        if not dw.finite(*acc, *gyro):
            self.report.bad("imu:not_finite", where, "IMU reading is not finite; message skipped")
            return
        self.imu_frame = self.imu_frame or msg.header.frame_id
        self.imu.append(dw.imu_row(_stamp(msg, bag_time, where, self.report), acc, gyro))

    def uwb_msg(self, msg, where, bag_time):
        """Fresh ranges (ra = 1) of one RTLSStick message; stale repeats (ra = 0) are counted."""
        self.stick_ids[msg.id] = self.stick_ids.get(msg.id, 0) + 1
        if len(self.stick_ids) > 1 and msg.id != next(iter(self.stick_ids)):
            self.report.bad("uwb:other_tag", where, f"ranges of a second tag (id {msg.id}) skipped")
            return
        t = _stamp(msg, bag_time, where, self.report)
        for k, r in enumerate(msg.ranges):
            self.report.count("uwb:ranges_in_messages")
            if r.ra == 0:
                self.report.count("uwb:stale_dropped")
                continue
            if r.ra != 1:
                self.report.bad("uwb:bad_ra", f"{where} range {k}", f"ra = {r.ra} is neither 0 nor 1; range skipped")
                continue
            if not dw.finite(r.range) or not dw.MIN_RANGE_M <= r.range <= dw.MAX_RANGE_M:
                self.report.bad("uwb:bad_range", f"{where} range {k}", f"range {r.range} m is not plausible; skipped")
                continue
            if r.id <= 0 or r.id == self.tag_id or r.id == IMU_ID:
                self.report.bad("uwb:bad_anchor_id", f"{where} range {k}", f"anchor id {r.id} is not usable; skipped")
                continue
            self.anchors_from_ranges.setdefault(r.id, (r.pos.x, r.pos.y, r.pos.z))
            self.ranges.append(dw.range_row(t, r.range, self.tag_id, r.id, "T", "A"))

    def anchors_msg(self, msg, where, bag_time):
        for a in msg.anchor:
            p = (a.position.x, a.position.y, a.position.z)
            if not dw.finite(*p) or a.id <= 0:
                self.report.bad("anchors:bad_entry", where, f"anchor id {a.id} at {p} skipped")
                continue
            old = self.anchors.setdefault(a.id, p)
            if max(abs(x - y) for x, y in zip(old, p)) > 1e-3:
                self.report.bad("anchors:moved", where, f"anchor {a.id} at {p}, first seen at {old}; first kept")

    def truth_msg(self, msg, where, bag_time):
        p, q = _pose_of(msg, self.types["truth"])
        if not dw.finite(*p) or not dw.quaternion_ok(q):
            self.report.bad("truth:bad_pose", where, "position not finite or quaternion norm far from 1; skipped")
            return
        self.truth_frames.add(msg.header.frame_id)
        self.truth.append(dw.tum_row(_stamp(msg, bag_time, where, self.report), p, q))

    def handle(self, role, msg, where, bag_time):
        getattr(self, role + "_msg")(msg, where, bag_time)


def _read(bag, topic_roles, collector, report):
    """One pass over the bag; each message is decoded on its own so that a bad one is counted."""
    total = sum(bag.get_message_count(topic_filters=[t]) for t in topic_roles)
    progress = dw.Progress("reading bag", total)
    index = {t: 0 for t in topic_roles}
    n = 0
    messages = bag.read_messages(topics=list(topic_roles), raw=True)
    while True:
        try:
            topic, raw, bag_time = next(messages)
        except StopIteration:
            break
        except Exception as ex:  # a damaged chunk or record: the reader cannot go on past it
            raise ValueError(f"{bag.filename}: damaged after {n} of {total} messages ({type(ex).__name__}: {ex}); "
                             "nothing written (a partial recording would look complete)") from None
        where = f"{topic} #{index[topic]}"
        index[topic] += 1
        n += 1
        progress.update(n)
        try:
            msg = raw[4]()
            msg.deserialize(raw[1])
            collector.handle(topic_roles[topic], msg, where, bag_time)
        except Exception as ex:  # a corrupt message must not stop the import
            report.bad(f"{topic}:undecodable", where, f"cannot decode ({type(ex).__name__}: {ex}); skipped")


def _topics(bag):
    info = bag.get_type_and_topic_info().topics
    return {name: (v.msg_type, v.message_count) for name, v in info.items()}


def _choose(topics, args):
    roles = {
        "imu": _pick(topics, (IMU_TYPE,), args.imu_topic, "imu", None),
        "uwb": _pick(topics, UWB_TYPES, args.uwb_topic, "uwb", None),
        "anchors": _pick(topics, ANCHOR_TYPES, args.anchors_topic, "anchors", None),
    }
    truth, why = choose_truth_topic(topics, args.truth_topic)
    roles["truth"] = truth
    dw.log(f"truth topic: {truth or 'none'} ({why})")
    if roles["uwb"] is None:
        raise ValueError("no UWB topic of type " + "/".join(UWB_TYPES) + " in the bag (give --uwb-topic)")
    used = {t for t in roles.values() if t}
    for name, (ty, cnt) in sorted(topics.items()):
        if name not in used:
            dw.log(f"not imported: {name} ({ty}, {cnt} messages)")
    return roles


def _write(out, c, roles, lever_arm, lever_src, args, report):
    anchors = c.anchors or c.anchors_from_ranges
    if not c.anchors:
        dw.log("no anchor list: anchor positions taken from the ranges' own 'pos' fields")
    if args.tag_id in anchors:
        raise ValueError(f"--tag-id {args.tag_id} is also an anchor id")
    dw.write_csv(os.path.join(out, "imu.csv"), dw.IMU_HEADER, dw.sort_by_time(c.imu, report, "imu.csv"))
    dw.write_csv(os.path.join(out, "ranges.csv"), dw.RANGES_HEADER, dw.sort_by_time(c.ranges, report, "ranges.csv"))
    noise, noise_note = None, "no noise figures: IMU not identified, the estimator's tuning defaults apply"
    if "waveshare" in (c.imu_frame + (roles["imu"] or "")).lower():
        noise = dict(ICM20948_NOISE)
        noise_note = (f"noise: {IN_USE_FACTOR:g} x the TDK ICM-20948 datasheet densities (Waveshare Sense HAT (B)), "
                      "in-use figures; bias random walks not given")
    dw.log(noise_note)
    dw.write_setup_yaml(os.path.join(out, "setup.yaml"), {args.tag_id: lever_arm}, anchors, IMU_ID, noise, comments=(
        f"imported from {os.path.basename(args.bag)} by ./meshnav import rosbag",
        f"tag {args.tag_id} (RTLS stick id {', '.join(map(str, c.stick_ids)) or '?'}): lever arm {lever_src}",
        "anchors: " + (f"topic {roles['anchors']}" if c.anchors else "ranges' pos fields"), noise_note))
    if c.truth:
        frame = ",".join(sorted(f for f in c.truth_frames if f)) or roles["truth"]
        dw.write_csv(os.path.join(out, "groundtruth.csv"), dw.TUM_HEADER, dw.sort_by_time(c.truth, report, "groundtruth.csv"))
        dw.write_truth_yaml(os.path.join(out, "truth.yaml"), anchors, frame, not args.truth_in_anchor_frame, comments=(
            f"groundtruth.csv: topic {roles['truth']} ({c.types['truth']}), pose of that sensor in frame '{frame}'",
            "anchor_positions: as the recording's anchor list gives them (not truth of another kind)"))
    else:
        dw.log("no ground truth written (no truth topic)")


def run(args):
    """Imports one bag; returns the process exit code."""
    import rosbag

    report = dw.Report()
    lever_arm, lever_src = _parse_lever_arm(args.tag_lever_arm)
    if args.tag_id <= 0 or args.tag_id == IMU_ID:
        raise ValueError(f"--tag-id {args.tag_id}: must be > 0 and not the IMU id {IMU_ID}")
    try:
        bag = rosbag.Bag(args.bag)
    except Exception as ex:
        raise ValueError(f"{args.bag}: cannot open as a ROS 1 bag ({type(ex).__name__}: {ex})")
    with bag:
        topics = _topics(bag)
        roles = _choose(topics, args)
        topic_roles = {t: r for r, t in roles.items() if t}
        types = {r: topics[t][0] for r, t in roles.items() if t}
        c = _Collector(roles, types, args.tag_id, report)
        _read(bag, topic_roles, c, report)
    dw.prepare_out_dir(args.out)
    _write(args.out, c, roles, lever_arm, lever_src, args, report)
    dw.log(f"wrote {args.out}: imu.csv {len(c.imu)} rows, ranges.csv {len(c.ranges)} rows "
           f"({report.counts['uwb:stale_dropped']} stale repeats dropped), groundtruth.csv {len(c.truth)} rows, "
           f"{len(c.anchors or c.anchors_from_ranges)} anchors")
    dw.log(f"counters: {report.summary()}")
    return 0
