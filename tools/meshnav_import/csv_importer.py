"""Your own CSV files -> meshnav dataset folder (docs/formats.md), described by a mapping file.

The mapping file (YAML; every key in docs/formats.md, "Importing your own CSVs"; examples in
config/import/) says, per stream, which CSV files to read (relative to the mapping file), their
delimiter and header, which column is which dataset field (by name or 0-based index), the units
(time s/ms/us/ns, range m/cm/mm, accelerometer m/s^2 or g, gyroscope rad/s or deg/s, pressure
Pa/hPa/kPa, or a number: SI units per unit of the file) and a time offset [s]; and the devices:
tags with their lever arms, anchors (inline or from a CSV), id mapping, IMU noise figures.

  ranges       required   -> ranges.csv
  imu          optional   -> imu.csv (without it the dataset holds ranges only: `meshnav run`
                             needs an IMU, range statistics and calibration with poses do not)
  groundtruth  optional   -> groundtruth.csv (TUM) and truth.yaml
  baro         optional   -> baro.csv
  (always)                -> setup.yaml (imu_id, tags, known anchors, noise figures)

Refused with file:line and the reason (exit 1): a field that is empty (required fields), NaN or
not a number, an id that is neither an integer nor a listed name, a row whose number of fields
differs from the header's (--skip-bad-rows skips and counts such rows instead). Dropped and
counted with file:line, as the dataset reader would: values beyond the plausibility limits (ranges
outside [-0.5, 500] m, IMU beyond 500 m/s^2 or 50 rad/s, pressure outside [1000, 200000] Pa,
quaternions of norm far from 1).
Rows out of time order are sorted (the count is printed). Units that look wrong (gyro median
above 10 rad/s, accelerometer median norm near 1 in m/s^2, median range above 100 m, a stream of
more than 30 days, ...) are refused naming the likely unit, unless --force.
"""

import math
import os
import re
import statistics
from decimal import Context, Decimal, InvalidOperation

from . import csv_mapping as cm
from . import dataset_writer as dw

BARO_HEADER = "t,pressure"
PLAIN_DECIMAL = re.compile(r"-?\d+(\.\d+)?")
TAG_TYPES = ("t", "84", "tag")
ANCHOR_TYPES = ("a", "65", "anchor")
LOS_TRUE = ("1", "1.0", "true", "yes", "los")
LOS_FALSE = ("0", "0.0", "false", "no", "nlos")
#: Largest |t| a meshnav time stamp holds [s] (common/time.h kMaxTimeSeconds).
MAX_TIME_S = 4.0e12
#: Plausibility limits of the dataset reader (common/plausibility.h).
MAX_ACC_M_S2, MAX_GYRO_RAD_S = 500.0, 50.0
MIN_PRESSURE_PA, MAX_PRESSURE_PA = 1000.0, 200000.0
MAX_R_M2 = dw.MAX_RANGE_M ** 2
#: A stream longer than this is taken as a time unit error [s].
MAX_SPAN_S = 30 * 86400.0
DATASET_FILES = ("imu.csv", "ranges.csv", "baro.csv", "groundtruth.csv", "setup.yaml", "truth.yaml",
                 "height.csv", "flight_state.csv")


class BadRow(Exception):
    """A row that cannot be read (not a plausibility drop): refused, or skipped with --skip-bad-rows."""


def add_arguments(p):
    p.add_argument("--map", required=True, metavar="FILE",
                   help="mapping file (YAML): docs/formats.md \"Importing your own CSVs\"; examples in config/import/")
    p.add_argument("--out", required=True, help="dataset folder to write (created)")
    p.add_argument("--base", metavar="DIR", help="folder the mapping's relative paths start from (default: the "
                   "mapping's 'base' key, else the mapping file's folder)")
    p.add_argument("--force", action="store_true",
                   help="import units that look wrong as declared (the check becomes a warning)")
    p.add_argument("--skip-bad-rows", action="store_true",
                   help="skip and count rows that cannot be read (empty, NaN, not a number, a wrong number of fields) "
                   "instead of stopping at the first")


# ----------------------------------------------------------------------------------------- values

_CTX = Context(prec=60)   # enough digits that the one rounding is the final float()


def _what(table, field):
    return f"{field} ({table.columns[field].describe()})"


def _dec(text, table, field):
    if not text:
        raise BadRow(f"{_what(table, field)} is empty")
    try:
        if "_" in text:
            raise InvalidOperation
        d = Decimal(text)
    except InvalidOperation:
        raise BadRow(f"{_what(table, field)} '{text}' is not a number") from None
    if not d.is_finite():
        raise BadRow(f"{_what(table, field)} '{text}' is not a finite number")
    return d


def _value(text, factor, table, field):
    """The number of `text` times `factor` (Decimal; exact before the one rounding to a double)."""
    if factor == 1:
        try:
            if "_" in text:
                raise ValueError
            x = float(text)
        except ValueError:
            x = None
        if x is None or not math.isfinite(x):
            _dec(text, table, field)  # raises with the reason
        return x
    return float(_CTX.multiply(_dec(text, table, field), factor)) + 0.0  # + 0.0: no "-0.0" from a sign flip


def _fmt_decimal(d):
    """Decimal seconds as plain text, at most nine decimals (ns), no exponent, no trailing zeros."""
    if d.as_tuple().exponent < -9:
        d = d.quantize(Decimal("1e-9"), context=_CTX)
    s = format(d, "f")
    if "." in s:
        s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _time(text, table):
    """(time text [s] for the dataset, seconds as float). Without conversion the recording's own
    text is kept digit for digit."""
    if table.time_factor == 1 and table.time_offset == 0 and PLAIN_DECIMAL.fullmatch(text or ""):
        return text, float(text)
    s = _CTX.add(_CTX.multiply(_dec(text, table, "t"), table.time_factor), table.time_offset)
    return _fmt_decimal(s), float(s)


def _median(xs):
    return statistics.median(xs) if xs else None


# ----------------------------------------------------------------------------------------- tables

def _split(line, delimiter):
    if delimiter is None:
        return line.split()
    if '"' in line:
        import csv
        return next(csv.reader([line], delimiter=delimiter))
    return line.split(delimiter)


def _resolve(table, names, path, lineno):
    """Field -> column index for a file with header `names` (or None: no header)."""
    out = {}
    for field, col in table.columns.items():
        if col.value is not None:
            continue
        if col.name is not None:
            hits = [i for i, n in enumerate(names) if n == col.name]
            if not hits:
                raise ValueError(f"{path}:{lineno}: missing column '{col.name}' ({table.key}.columns.{field}; "
                                 f"header has: {', '.join(names)})")
            if len(hits) > 1:
                raise ValueError(f"{path}:{lineno}: column '{col.name}' ({table.key}.columns.{field}) appears "
                                 f"{len(hits)} times in the header; give its 0-based index instead")
            out[field] = hits[0]
        else:
            out[field] = col.index
    return out


class _Import:
    def __init__(self, args, mapping):
        self.args, self.m = args, mapping
        self.report = dw.Report()
        self.problems = []           # unit plausibility: (message)
        self.devices = {}            # meshnav id -> 'T'/'A' as seen in the ranges
        self.unlisted_tags = set()
        self.sources = []

    # -- reading one table --------------------------------------------------------------------
    def rows(self, table, path):
        """Yields (where, {field: text}) for every data row of one file of `table`."""
        name = os.path.basename(path)
        if not os.path.isfile(path):
            raise ValueError(f"{path}: no such file ({table.key}.path)")
        self.sources.append(os.path.realpath(path))
        progress = dw.Progress(f"reading {name}", os.path.getsize(path))
        pos, header_pending, nfields, idx = 0, table.header, None, None
        if not table.header:
            idx = {f: c.index for f, c in table.columns.items() if c.value is None}
        consts = {f: c.value for f, c in table.columns.items() if c.value is not None}
        try:
            with open(path, encoding="utf-8-sig", newline="") as f:
                for lineno, raw in enumerate(f, 1):
                    pos += len(raw)
                    if lineno % 8192 == 0:
                        progress.update(pos)
                    if lineno <= table.skip_lines:
                        continue
                    line = raw.rstrip("\r\n")
                    stripped = line.strip()
                    if not stripped:
                        continue
                    if header_pending:
                        if table.comment and stripped.startswith(table.comment):
                            line = stripped[len(table.comment):]
                        names = [n.strip() for n in _split(line, table.delimiter)]
                        idx = _resolve(table, names, path, lineno)
                        nfields, header_pending = len(names), False
                        continue
                    if table.comment and stripped.startswith(table.comment):
                        continue
                    fields = [x.strip() for x in _split(line, table.delimiter)]
                    where = f"{path}:{lineno}"
                    if nfields is None:
                        nfields = len(fields)
                        too_far = {fl: i for fl, i in idx.items() if i >= nfields}
                        if too_far:
                            fl, i = next(iter(too_far.items()))
                            raise ValueError(f"{where}: {table.key}.columns.{fl} is column index {i} (0-based), but "
                                             f"the first row has {nfields} fields (delimiter "
                                             f"{'whitespace' if table.delimiter is None else repr(table.delimiter)})")
                    while len(fields) > nfields and fields[-1] == "":
                        fields.pop()
                    if len(fields) != nfields:
                        ref = "header has" if table.header else "first row has"
                        delim = "whitespace" if table.delimiter is None else repr(table.delimiter)
                        yield where, BadRow(f"{len(fields)} fields where the {ref} {nfields} (delimiter {delim})")
                        continue
                    texts = {fl: fields[i] for fl, i in idx.items()}
                    texts.update(consts)
                    yield where, texts
        except UnicodeDecodeError as ex:
            raise ValueError(f"{path}: not UTF-8 text ({ex.reason} at byte {ex.start})") from None
        if header_pending:
            raise ValueError(f"{path}: no header line (the table has header: true)")

    def read(self, table, build, timed=True):
        """Rows of every file of `table` (each file sorted by time, then merged by time)."""
        out = []
        for path in table.paths:
            name = os.path.basename(path)
            rows, bad = [], 0
            for where, texts in self.rows(table, path):
                try:
                    if isinstance(texts, BadRow):
                        raise texts
                    row = build(texts, table, name, where)
                except BadRow as ex:
                    if not self.args.skip_bad_rows:
                        raise ValueError(f"{where}: {ex} (--skip-bad-rows skips and counts such rows)") from None
                    self.report.bad(f"{name}:bad_row", where, f"{ex}; row skipped")
                    bad += 1
                    continue
                if row is not None:
                    rows.append(row)
            dw.log(f"{path}: {len(rows)} rows" + (f", {bad} unreadable rows skipped" if bad else ""))
            out += dw.sort_by_time(rows, self.report, name) if timed else rows
        if timed and len(table.paths) > 1:
            out.sort(key=lambda r: float(r[0]))
        return out

    @staticmethod
    def num(texts, table, field):
        return _value(texts[field], table.scaled[field], table, field)

    def device(self, texts, table, field):
        text = texts[field]
        if not text:
            raise BadRow(f"{_what(table, field)} is empty")
        out = cm.map_id(self.m, text)
        if out is None:
            raise BadRow(f"{_what(table, field)} '{text}' is neither an id >= 0 nor listed in ids.map")
        if out <= 0:
            raise BadRow(f"{_what(table, field)} '{text}' becomes meshnav id {out}; ids must be > 0 "
                         "(set ids.offset or ids.map)")
        return out

    # -- streams --------------------------------------------------------------------------------
    def ranges(self):
        stats = {"range": [], "t": []}
        kinds = self.report.counts

        def build(texts, table, name, where):
            t_text, t = _time(texts["t"], table)
            raw = self.num(texts, table, "range_raw")
            c = table.columns
            if "tag_id" in c:
                ids = (self.device(texts, table, "tag_id"), self.device(texts, table, "anchor_id"))
                types = ("T", "A")
            else:
                ids = (self.device(texts, table, "UWB_ID1"), self.device(texts, table, "UWB_ID2"))
                if "type_ID1" in c:
                    types = tuple(self.type_of(texts, table, f) for f in ("type_ID1", "type_ID2"))
                else:
                    types = tuple("T" if i in self.m.tags else "A" for i in ids)
            if ids[0] == ids[1]:
                raise BadRow(f"range from device {ids[0]} to itself")
            for i, ty in zip(ids, types):
                if ty == "T" and i in self.m.anchors:
                    raise BadRow(f"device {i} is an anchor of the mapping but its type here is T")
                if ty == "A" and i in self.m.tags:
                    raise BadRow(f"device {i} is a tag of the mapping but its type here is A")
                if self.devices.setdefault(i, ty) != ty:
                    raise BadRow(f"device {i} is {self.devices[i]} in earlier rows but {ty} here")
            corr = raw
            if "range_corr" in c and texts["range_corr"] != "":
                corr = self.num(texts, table, "range_corr")
            var = 0.0
            if "R" in c and texts["R"] != "":
                unit = table.factors["range_raw"]  # R is in the range unit squared, then the column's scale
                var = _value(texts["R"], unit * unit * (c["R"].scale or 1), table, "R")
            if "sigma" in c and texts["sigma"] != "":
                self.num(texts, table, "sigma")  # refuses what is not a finite number
                sd = _CTX.multiply(_dec(texts["sigma"], table, "sigma"), table.scaled["sigma"])
                var = float(_CTX.multiply(sd, sd))
            los = "1"
            if "LOS" in c and texts["LOS"] != "":
                v = texts["LOS"].lower()
                if v not in LOS_TRUE + LOS_FALSE:
                    raise BadRow(f"{_what(table, 'LOS')} '{texts['LOS']}' is not 1/0/true/false")
                los = "1" if v in LOS_TRUE else "0"
            stats["range"].append(raw)
            stats["t"].append(t)
            if raw < dw.MIN_RANGE_M:
                self.report.bad(f"{name}:negative_range", where,
                                f"range {raw!r} m is below {dw.MIN_RANGE_M} m; row dropped")
                return None
            if raw > dw.MAX_RANGE_M:
                self.report.bad(f"{name}:absurd_range", where,
                                f"range {raw!r} m is beyond {dw.MAX_RANGE_M} m; row dropped")
                return None
            if not dw.MIN_RANGE_M <= corr <= dw.MAX_RANGE_M:
                self.report.bad(f"{name}:bad_range_corr", where, f"range_corr {corr!r} m is not plausible; row dropped")
                return None
            if not 0.0 <= var <= MAX_R_M2:
                self.report.bad(f"{name}:bad_R", where, f"variance {var!r} m^2 is not in [0, 500^2]; row dropped")
                return None
            for i, ty in zip(ids, types):
                if ty == "T" and i not in self.m.tags and i not in self.unlisted_tags:
                    self.unlisted_tags.add(i)
                    dw.log(f"{where}: tag {i} is not in the mapping's tags (no lever arm): its ranges are kept, "
                           "the estimator does not use a tag setup.yaml does not list")
            kind = {("A", "T"): "tag_anchor", ("T", "T"): "tag_tag", ("A", "A"): "anchor_anchor"}[tuple(sorted(types))]
            kinds[f"ranges:{kind}"] += 1
            r_text = "0" if var == 0 else dw.num(var)
            return [t_text, dw.num(raw), dw.num(corr), r_text, str(ids[0]), str(ids[1]), types[0], types[1], los]

        rows = []
        for table in self.m.streams["ranges"]:
            rows += self.read(table, build)
        if len(self.m.streams["ranges"]) > 1:
            rows.sort(key=lambda r: float(r[0]))
        self.check_time("ranges", stats["t"], self.m.streams["ranges"][0])
        med = _median(stats["range"])
        unit = self.m.streams["ranges"][0].units["range_unit"]
        if med is not None and med > 100.0:
            self.problems.append(
                f"ranges: median range {med:.4g} m with range_unit {unit}: UWB ranges of a room or hall are below "
                f"100 m; this looks like millimetres (range_unit: mm, median {med / 1000:.4g} m) or centimetres "
                f"(range_unit: cm, median {med / 100:.4g} m)")
        elif med is not None and med < 0.05:
            self.problems.append(
                f"ranges: median range {med:.4g} m with range_unit {unit}: implausibly short; this looks like "
                f"metres declared as a smaller unit (range_unit: m)")
        self.range_stats = stats
        return rows

    def type_of(self, texts, table, field):
        v = texts[field]
        if v.lower() in TAG_TYPES:
            return "T"
        if v.lower() in ANCHOR_TYPES:
            return "A"
        raise BadRow(f"{_what(table, field)} '{v}' is not a device type (T/A, 84/65, tag/anchor)")

    def imu(self):
        acc_n, gyro_n, ts = [], [], []
        axes = ("x", "y", "z")

        def build(texts, table, name, where):
            t_text, t = _time(texts["t"], table)
            acc = [self.num(texts, table, "lin_acc_" + a) for a in axes]
            gyro = [self.num(texts, table, "ang_vel_" + a) for a in axes]
            a, g = math.sqrt(sum(v * v for v in acc)), math.sqrt(sum(v * v for v in gyro))
            acc_n.append(a)
            gyro_n.append(g)
            ts.append(t)
            if a > MAX_ACC_M_S2 or g > MAX_GYRO_RAD_S:
                self.report.bad(f"{name}:absurd_value", where, f"IMU reading |a| {a:.4g} m/s^2, |w| {g:.4g} rad/s is "
                                "beyond 500 m/s^2 or 50 rad/s; row dropped")
                return None
            return dw.imu_row(t_text, acc, gyro)

        rows = []
        for table in self.m.streams["imu"]:
            rows += self.read(table, build)
        if len(self.m.streams["imu"]) > 1:
            rows.sort(key=lambda r: float(r[0]))
        table = self.m.streams["imu"][0]
        self.check_time("imu", ts, table)
        ga, gg = _median(acc_n), _median(gyro_n)
        au, gu = table.units["acc_unit"], table.units["gyro_unit"]
        g99 = sorted(gyro_n)[int(0.99 * (len(gyro_n) - 1))] if gyro_n else None
        if gg is not None and gg > 10.0:
            self.problems.append(
                f"imu: median |angular rate| {gg:.4g} rad/s with gyro_unit {gu}: no rig turns that fast most of the "
                f"time; this looks like deg/s (gyro_unit: deg/s, median {math.radians(gg):.4g} rad/s)")
        elif g99 is not None and g99 > 35.0:
            self.problems.append(
                f"imu: 1 % of the angular rates exceed {g99:.4g} rad/s with gyro_unit {gu}, beyond the full scale of "
                f"MEMS gyroscopes (2000 deg/s = 35 rad/s); this looks like deg/s (gyro_unit: deg/s)")
        if ga is not None:
            if 0.5 <= ga <= 2.0:
                self.problems.append(
                    f"imu: median |specific force| {ga:.4g} m/s^2 with acc_unit {au}: about 1, as an accelerometer in "
                    f"g reads (acc_unit: g, median {ga * 9.80665:.4g} m/s^2); meshnav needs about 9.81 at rest")
            elif ga < 0.5:
                self.problems.append(
                    f"imu: median |specific force| {ga:.4g} m/s^2 with acc_unit {au}: far below 9.81; is gravity "
                    "removed (a 'linear acceleration' output)? meshnav needs the specific force, gravity included")
            elif ga > 50.0:
                hint = ("this looks like m/s^2 declared as g (acc_unit: m/s^2)" if au == "g"
                        else "check acc_unit and the columns' scale")
                self.problems.append(f"imu: median |specific force| {ga:.4g} m/s^2 with acc_unit {au}: {hint}")
            elif not 7.0 <= ga <= 13.0:
                dw.log(f"warning: imu: median |specific force| {ga:.4g} m/s^2 is far from 9.81 (acc_unit {au})")
        self.imu_times = ts
        return rows

    def groundtruth(self):
        norms, ts = [], []

        def build(texts, table, name, where):
            t_text, t = _time(texts["t"], table)
            p = [self.num(texts, table, f) for f in ("tx", "ty", "tz")]
            q = [self.num(texts, table, f) for f in ("qx", "qy", "qz", "qw")]
            norms.append(math.sqrt(sum(v * v for v in p)))
            ts.append(t)
            if not dw.quaternion_ok(q):
                self.report.bad(f"{name}:bad_quaternion", where, "quaternion norm far from 1; row dropped")
                return None
            return dw.tum_row(t_text, p, q)

        rows = []
        for table in self.m.streams["groundtruth"]:
            rows += self.read(table, build)
        if len(self.m.streams["groundtruth"]) > 1:
            rows.sort(key=lambda r: float(r[0]))
        table = self.m.streams["groundtruth"][0]
        self.check_time("groundtruth", ts, table)
        med = _median(norms)
        if med is not None and med > 1000.0:
            self.problems.append(f"groundtruth: median distance from the origin {med:.4g} m with position_unit "
                                 f"{table.units['position_unit']}: this looks like millimetres (position_unit: mm)")
        return rows

    def baro(self):
        ps, ts = [], []

        def build(texts, table, name, where):
            t_text, t = _time(texts["t"], table)
            p = self.num(texts, table, "pressure")
            ps.append(p)
            ts.append(t)
            if not MIN_PRESSURE_PA <= p <= MAX_PRESSURE_PA:
                self.report.bad(f"{name}:bad_value", where, f"pressure {p!r} Pa is not plausible; row dropped")
                return None
            return [t_text, dw.num(p)]

        rows = []
        for table in self.m.streams["baro"]:
            rows += self.read(table, build)
        if len(self.m.streams["baro"]) > 1:
            rows.sort(key=lambda r: float(r[0]))
        table = self.m.streams["baro"][0]
        self.check_time("baro", ts, table)
        med = _median(ps)
        unit = table.units["pressure_unit"]
        if med is not None and not 20000.0 <= med <= 120000.0:
            guess = ("hPa or mbar (pressure_unit: hPa)" if 200.0 <= med <= 1200.0 else
                     "kPa (pressure_unit: kPa)" if 20.0 <= med <= 120.0 else "none of Pa, hPa, kPa")
            self.problems.append(f"baro: median pressure {med:.6g} Pa with pressure_unit {unit}: air pressure is "
                                 f"20000-120000 Pa; this looks like {guess}")
        return rows

    def anchors_file(self):
        table = self.m.anchors_file
        out = {}

        def build(texts, table, name, where):
            i = self.device(texts, table, "id")
            p = tuple(self.num(texts, table, f) for f in ("x", "y", "z"))
            if i in out or i in self.m.anchors:
                raise ValueError(f"{where}: anchor {i} is given twice (anchors and anchors_file, or twice in the file)")
            if i in self.m.tags:
                raise ValueError(f"{where}: anchor {i} is also a tag of the mapping")
            out[i] = p
            return i

        self.read(table, build, timed=False)
        if not out:
            raise ValueError(f"{table.paths[0]}: anchors_file holds no anchor")
        return out

    def check_time(self, stream, ts, table):
        if not ts:
            return
        lo, hi = min(ts), max(ts)
        unit = table.units.get("time_unit", "s")
        if max(abs(lo), abs(hi)) > MAX_TIME_S:
            self.problems.append(f"{stream}: times up to {max(abs(lo), abs(hi)):.4g} s with time_unit {unit} do not "
                                 f"fit a meshnav time stamp (|t| <= 4e12 s); this looks like a finer time unit "
                                 f"({self.time_guess(hi - lo, unit)})")
        elif hi - lo > MAX_SPAN_S:
            self.problems.append(f"{stream}: the stream spans {(hi - lo) / 86400:.4g} days with time_unit {unit}; "
                                 f"this looks like a finer time unit ({self.time_guess(hi - lo, unit)})")

    @staticmethod
    def time_guess(span, unit):
        for name, f in (("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)):
            if span * f <= 2 * 86400.0:
                return f"time_unit: {name} would give {span * f:.4g} s of recording"
        return "time_unit: ns or coarser still"

    # -- whole import ---------------------------------------------------------------------------
    def overlap(self, ranges_rows):
        if not getattr(self, "imu_times", None) or not self.range_stats["t"]:
            return
        a0, a1 = min(self.imu_times), max(self.imu_times)
        b0, b1 = min(self.range_stats["t"]), max(self.range_stats["t"])
        common = min(a1, b1) - max(a0, b0)
        if common <= 0:
            self.problems.append(f"imu [{a0:.6f}, {a1:.6f}] s and ranges [{b0:.6f}, {b1:.6f}] s do not overlap in "
                                 "time: check time_unit and time_offset of both streams")
        elif common < 0.5 * (b1 - b0):
            dw.log(f"warning: imu [{a0:.6f}, {a1:.6f}] s covers only {100 * common / max(b1 - b0, 1e-9):.0f} % of "
                   f"the ranges [{b0:.6f}, {b1:.6f}] s")

    def imu_id(self):
        used = set(self.m.tags) | set(self.m.anchors) | set(self.devices)
        if self.m.imu_id not in used:
            return self.m.imu_id
        if self.m.imu_id_given:
            raise ValueError(f"{self.m.path}:{self.m.imu_id_given}: key 'ids.imu' = {self.m.imu_id} is also a tag or "
                             "anchor id")
        free = next(i for i in range(1, max(used) + 2) if i not in used)
        dw.log(f"imu_id: the default 1 is a tag or anchor id; using {free} (set ids.imu to choose)")
        return free

    def check_out(self, out, writes):
        out = os.path.abspath(out)
        for name in writes:
            p = os.path.realpath(os.path.join(out, name))
            if p in self.sources:
                raise ValueError(f"--out {out}: would overwrite the source {p}; choose another folder")
        if os.path.isdir(out):
            stale = [n for n in DATASET_FILES if n not in writes and os.path.exists(os.path.join(out, n))]
            if stale:
                raise ValueError(f"--out {out} already holds {', '.join(stale)}, which this import does not write "
                                 "(the dataset would mix two recordings); remove them or choose another folder")


def run(args):
    """Imports the CSVs a mapping file describes; returns the process exit code."""
    m = cm.load(args.map, args.base)
    imp = _Import(args, m)
    anchors = dict(m.anchors)
    if m.anchors_file:
        anchors.update(imp.anchors_file())
        m.anchors = anchors
    ranges = imp.ranges()
    imu = imp.imu() if "imu" in m.streams else None
    gt = imp.groundtruth() if "groundtruth" in m.streams else None
    baro = imp.baro() if "baro" in m.streams else None
    imp.overlap(ranges)
    if imp.problems:
        if not args.force:
            raise ValueError(f"{args.map}: the data does not fit the declared units:\n  " + "\n  ".join(imp.problems) +
                             "\n  (fix the mapping, or --force to import as declared)")
        for p in imp.problems:
            dw.log(f"warning: {p} (--force: imported as declared)")
    for kind, rows in (("ranges", ranges), ("imu", imu), ("groundtruth", gt), ("baro", baro)):
        if rows is not None and not rows:
            raise ValueError(f"{args.map}: {kind}: no row is left to write (every row was dropped; see the messages "
                             "above)")
    imu_id = imp.imu_id()

    writes = ["ranges.csv", "setup.yaml"] + ["imu.csv"] * (imu is not None) + ["baro.csv"] * (baro is not None) + \
        ["groundtruth.csv", "truth.yaml"] * (gt is not None)
    imp.check_out(args.out, writes)
    out = dw.prepare_out_dir(args.out)
    dw.write_csv(os.path.join(out, "ranges.csv"), dw.RANGES_HEADER, ranges)
    if imu is not None:
        dw.write_csv(os.path.join(out, "imu.csv"), dw.IMU_HEADER, imu)
    if baro is not None:
        dw.write_csv(os.path.join(out, "baro.csv"), BARO_HEADER, baro)
    units = "; ".join(f"{k}: " + ", ".join(f"{u} {v}" for u, v in t[0].units.items())
                      for k, t in m.streams.items() if t[0].units)
    comments = [f"imported by ./meshnav import csv --map {args.map}"]
    if m.description:
        comments.append(m.description)
    comments.append(f"units: {units}")
    if m.id_offset or m.id_map:
        listed = ", ".join(f"{k} -> {v}" for k, v in sorted(m.id_map.items(), key=lambda kv: str(kv[0])))
        comments.append(f"ids: recording id + {m.id_offset}" + (f", except {listed}" if listed else ""))
    if not m.noise:
        comments.append("no noise figures in the mapping: the estimator's defaults apply")
    if imu is None:
        comments.append("ranges only: no imu.csv (meshnav run needs one; range statistics and calibration with "
                        "given poses do not)")
    dw.write_setup_yaml(os.path.join(out, "setup.yaml"), m.tags, anchors, imu_id, m.noise or None, comments=comments)
    if gt is not None:
        dw.write_csv(os.path.join(out, "groundtruth.csv"), dw.TUM_HEADER, gt)
        extra = m.streams["groundtruth"][0].extra
        frame = extra.get("frame", "G")
        dw.write_truth_yaml(os.path.join(out, "truth.yaml"), anchors, frame, extra.get("align_required", False),
                            comments=(f"groundtruth.csv: imported by ./meshnav import csv --map "
                                      f"{args.map}", "anchor_positions: the mapping's anchors"))
    c = imp.report.counts
    unknown = sorted(i for i, ty in imp.devices.items() if ty == "A" and i not in anchors)
    dw.log(f"wrote {out}: ranges.csv {len(ranges)} rows ({c['ranges:tag_anchor']} tag-anchor, "
           f"{c['ranges:anchor_anchor']} anchor-anchor, {c['ranges:tag_tag']} tag-tag), "
           + (f"imu.csv {len(imu)} rows, " if imu is not None else "")
           + (f"groundtruth.csv {len(gt)} rows, " if gt is not None else "")
           + (f"baro.csv {len(baro)} rows, " if baro is not None else "")
           + f"setup.yaml ({len(m.tags)} tags, {len(anchors)} known anchors, imu_id {imu_id})")
    if unknown:
        dw.log(f"anchors without a position in the mapping (unknown, for the calibrator): {unknown}")
    if imu is None:
        dw.log("no imu stream in the mapping: the dataset holds ranges only (no imu.csv). `./meshnav run` needs "
               "imu.csv (the estimator propagates on the IMU); ranges-only data serves meshnav_range_stats and "
               "meshnav_calibrate (with groundtruth.csv or --poses)")
    dw.log(f"counters: {imp.report.summary()}")
    return 0
