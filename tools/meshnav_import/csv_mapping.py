"""The mapping file of `./meshnav import csv` (docs/formats.md, "Importing your own CSVs"): loads it,
checks every key and value, and returns plain objects for csv_importer.

Every error names the mapping file, the line and the key (`map.yaml:12: key 'imu.gyro_unit' ...`);
a key this module does not know is refused, never ignored.
"""

import glob
import os
import re
from decimal import Decimal, InvalidOperation

from . import dataset_writer as dw

#: Unit names -> how many SI units (s, m, m/s², rad/s, Pa) one unit of the file is. Exact decimal
#: texts, so that ms -> s or mm -> m conversions give the double nearest to the exact value.
TIME_UNITS = {"s": "1", "ms": "0.001", "us": "0.000001", "µs": "0.000001", "ns": "0.000000001"}
LENGTH_UNITS = {"m": "1", "cm": "0.01", "mm": "0.001"}
ACC_UNITS = {"m/s^2": "1", "m/s2": "1", "m/s²": "1", "g": "9.80665"}
GYRO_UNITS = {"rad/s": "1", "deg/s": "0.01745329251994329576923690768488612713442871888541725456"}
PRESSURE_UNITS = {"Pa": "1", "hPa": "100", "mbar": "100", "kPa": "1000"}

#: setup.yaml `noise:` keys (docs/formats.md) and whether 0 is allowed (the random walks).
NOISE_KEYS = {"sigma_range": False, "imu_acc_noise_density": False, "imu_gyro_noise_density": False,
              "imu_acc_bias_rw": True, "imu_gyro_bias_rw": True, "imu_acc_bias_sigma": False,
              "imu_gyro_bias_sigma": False, "baro_pressure_sigma": False}

#: Per stream: its fields (dataset columns; `None`: required, else optional), its unit keys
#: {key: (unit table, default, fields it applies to)}, and further keys of the stream.
RANGE_ID_FIELDS = ("UWB_ID1", "UWB_ID2", "type_ID1", "type_ID2", "tag_id", "anchor_id")
STREAMS = {
    "ranges": {
        "fields": {"t": None, "range_raw": None, "range_corr": "opt", "R": "opt", "sigma": "opt", "LOS": "opt",
                   "UWB_ID1": "opt", "UWB_ID2": "opt", "type_ID1": "opt", "type_ID2": "opt",
                   "tag_id": "opt", "anchor_id": "opt"},
        "units": {"range_unit": (LENGTH_UNITS, "m", ("range_raw", "range_corr", "sigma"))},
    },
    "imu": {
        "fields": {k: None for k in ("t", "lin_acc_x", "lin_acc_y", "lin_acc_z", "ang_vel_x", "ang_vel_y", "ang_vel_z")},
        "units": {"acc_unit": (ACC_UNITS, "m/s^2", ("lin_acc_x", "lin_acc_y", "lin_acc_z")),
                  "gyro_unit": (GYRO_UNITS, "rad/s", ("ang_vel_x", "ang_vel_y", "ang_vel_z"))},
    },
    "groundtruth": {
        "fields": {k: None for k in ("t", "tx", "ty", "tz", "qx", "qy", "qz", "qw")},
        "units": {"position_unit": (LENGTH_UNITS, "m", ("tx", "ty", "tz"))},
        "extra": ("frame", "align_required"),
    },
    "baro": {
        "fields": {"t": None, "pressure": None},
        "units": {"pressure_unit": (PRESSURE_UNITS, "Pa", ("pressure",))},
    },
}
ANCHORS_FILE_FIELDS = ("id", "x", "y", "z")
TABLE_KEYS = ("path", "delimiter", "header", "skip_lines", "comment", "columns")
TOP_KEYS = ("version", "description", "base", "ids", "tags", "anchors", "anchors_file", "noise") + tuple(STREAMS)


class MappingError(ValueError):
    pass


class _Map(dict):
    """A YAML map that remembers the line of each key."""

    def __init__(self, line):
        super().__init__()
        self.line = line
        self.lines = {}


def _yaml_loader():
    import yaml

    class Loader(yaml.SafeLoader):
        pass

    def construct_map(loader, node):
        loader.flatten_mapping(node)
        out = _Map(node.start_mark.line + 1)
        for key_node, value_node in node.value:
            key = loader.construct_object(key_node, deep=True)
            line = key_node.start_mark.line + 1
            if not isinstance(key, (str, int)) or isinstance(key, bool):
                raise MappingError(f"{loader.name}:{line}: key {key!r} is neither a name nor an integer id")
            if key in out:
                raise MappingError(f"{loader.name}:{line}: key '{key}' is given twice (first on line {out.lines[key]})")
            out[key] = loader.construct_object(value_node, deep=True)
            out.lines[key] = line
        return out

    Loader.add_constructor("tag:yaml.org,2002:map", construct_map)
    return yaml, Loader


class Column:
    """Where a field's text comes from: a column by `name` or 0-based `index`, or a constant `value`;
    `scale` multiplies after the unit (e.g. -1 for an axis that points the other way)."""

    def __init__(self, name=None, index=None, value=None, scale=None):
        self.name, self.index, self.value, self.scale = name, index, value, scale

    def describe(self):
        if self.value is not None:
            return f"constant {self.value!r}"
        return f"column '{self.name}'" if self.name is not None else f"column index {self.index}"


class Table:
    """One CSV source: its files and how to read them, and the columns of its fields."""

    def __init__(self):
        self.paths, self.delimiter, self.header, self.skip_lines, self.comment = [], ",", True, 0, "#"
        self.columns = {}       # field -> Column
        self.factors = {}       # field -> Decimal unit factor (without the column's scale)
        self.scaled = {}        # field -> Decimal unit factor times the column's scale
        self.units = {}         # unit key -> text as given
        self.time_factor, self.time_offset = Decimal(1), Decimal(0)
        self.extra = {}
        self.key = ""           # 'imu', 'ranges[1]', 'anchors_file'


class Mapping:
    def __init__(self, path):
        self.path = path
        self.base = os.path.dirname(os.path.abspath(path))
        self.description = None
        self.id_offset, self.id_map, self.imu_id, self.imu_id_given = 0, {}, 1, False
        self.tags, self.anchors, self.anchors_file, self.noise = {}, {}, None, {}
        self.streams = {}       # kind -> [Table]


class _Reader:
    """Reads the values of one mapping file; every message names the file, the line and the key."""

    def __init__(self, path):
        self.path = path

    def fail(self, where, key, what):
        """Refuses `key` (its full dotted name) of the map `where`, at the line of its last part."""
        line = "?"
        if isinstance(where, _Map):
            last = key.rsplit(".", 1)[-1]
            line = next((n for k, n in where.lines.items() if str(k) == last), where.line)
        raise MappingError(f"{self.path}:{line}: key '{key}' {what}")

    def fail_node(self, node, key, what):
        line = node.line if isinstance(node, _Map) else "?"
        raise MappingError(f"{self.path}:{line}: key '{key}' {what}")

    def check_keys(self, node, prefix, allowed):
        for k in node:
            if k not in allowed:
                full = f"{prefix}.{k}" if prefix else str(k)
                raise MappingError(f"{self.path}:{node.lines[k]}: unknown key '{full}' (known here: "
                                   f"{', '.join(allowed)})")

    def map(self, parent, key, full, required=False):
        v = parent.get(key)
        if v is None:
            if required:
                self.fail(parent, full, "is required")
            return None
        if not isinstance(v, _Map):
            self.fail(parent, full, f"must be a map, got {v!r}")
        return v

    def number(self, parent, key, full, v=None):
        v = parent[key] if v is None else v
        try:
            if isinstance(v, bool):
                raise ValueError
            x = float(v)
        except (TypeError, ValueError):
            self.fail(parent, full, f"must be a number, got {v!r}")
        if not dw.finite(x):
            self.fail(parent, full, f"must be a finite number, got {v!r}")
        return x

    def decimal(self, parent, key, full):
        x = self.number(parent, key, full)
        return Decimal(str(parent[key]).strip()) if isinstance(parent[key], str) else Decimal(repr(x))

    def integer(self, parent, key, full, minimum=None):
        v = parent[key]
        if isinstance(v, bool) or not isinstance(v, int):
            self.fail(parent, full, f"must be an integer, got {v!r}")
        if minimum is not None and v < minimum:
            self.fail(parent, full, f"must be >= {minimum}, got {v}")
        return v

    def boolean(self, parent, key, full):
        v = parent[key]
        if not isinstance(v, bool):
            self.fail(parent, full, f"must be true or false, got {v!r}")
        return v

    def text(self, parent, key, full):
        v = parent[key]
        if not isinstance(v, str) or not v:
            self.fail(parent, full, f"must be a non-empty text, got {v!r}")
        return v

    def vec3(self, parent, key, full):
        v = parent[key]
        if not isinstance(v, list) or len(v) != 3:
            self.fail(parent, full, f"must be a list of 3 numbers [m], got {v!r}")
        return tuple(self.number(parent, key, full, x) for x in v)

    def unit(self, parent, key, full, table):
        """A unit name of `table` or a positive number (SI units per unit of the file)."""
        v = parent[key]
        if isinstance(v, str) and v.strip() in table:
            return Decimal(table[v.strip()]), v.strip()
        try:
            if isinstance(v, bool):
                raise ValueError
            d = Decimal(str(v).strip())
            ok = d.is_finite() and d > 0
        except (InvalidOperation, ValueError):
            ok = False
        if not ok:
            self.fail(parent, full, f"must be one of {', '.join(table)} or a positive number (SI units per unit of "
                      f"the file), got {v!r}")
        return d, str(v)


def canonical_id(v):
    """A recording's device id as a key: integers (also '12', '12.0' as text) as int, else the text."""
    if isinstance(v, int) and not isinstance(v, bool):
        return v
    s = str(v).strip()
    if re.fullmatch(r"[+-]?\d+(\.0*)?", s):
        return int(float(s)) if "." in s else int(s)
    return s


def map_id(mapping, v):
    """meshnav id of a recording's device id `v` (ids.map first, then + ids.offset); None when the
    id is neither listed nor an integer."""
    key = canonical_id(v)
    if key in mapping.id_map:
        return mapping.id_map[key]
    if isinstance(key, int) and key >= 0:
        return key + mapping.id_offset
    return None


def _column(r, node, key, full, header):
    v = node[key]
    if isinstance(v, bool):
        r.fail(node, full, f"must be a column name, a 0-based column index or a map, got {v!r}")
    if isinstance(v, int):
        if v < 0:
            r.fail(node, full, f"column index must be >= 0 (0-based), got {v}")
        return Column(index=v)
    if isinstance(v, str) and v:
        if not header:
            r.fail(node, full, f"names column '{v}' but the table has header: false; give a 0-based column index")
        return Column(name=v)
    if isinstance(v, _Map):
        r.check_keys(v, full, ("column", "scale", "value"))
        if ("column" in v) == ("value" in v):
            r.fail_node(v, full, "needs exactly one of 'column' (name or 0-based index) and 'value' (a constant)")
        if "value" in v:
            if "scale" in v:
                r.fail(v, full + ".scale", "does not go with 'value' (give the constant as it should be)")
            c = v["value"]
            if isinstance(c, (bool, list, dict)) or c is None:
                r.fail(v, full + ".value", f"must be a number or a text, got {c!r}")
            return Column(value=str(c))
        col = _column(r, v, "column", full + ".column", header)
        if "scale" in v:
            col.scale = r.decimal(v, "scale", full + ".scale")
            if col.scale == 0:
                r.fail(v, full + ".scale", "must not be 0")
        return col
    r.fail(node, full, f"must be a column name, a 0-based column index or a map, got {v!r}")


def _paths(r, node, full, base):
    v = node.get("path")
    if v is None:
        r.fail(node, full, "needs 'path': the CSV file (or a list of files, glob patterns allowed), relative to "
               "the mapping file's folder (or to 'base')")
    items = v if isinstance(v, list) else [v]
    if not items:
        r.fail(node, full + ".path", "is an empty list")
    out = []
    for item in items:
        if not isinstance(item, str) or not item:
            r.fail(node, full + ".path", f"must be a file name or a list of them, got {item!r}")
        p = os.path.normpath(os.path.join(base, os.path.expanduser(item)))
        if any(ch in item for ch in "*?["):
            found = sorted(glob.glob(p))
            if not found:
                r.fail(node, full + ".path", f"pattern '{item}' matches no file (looked in {os.path.dirname(p)})")
            out += found
        else:
            out.append(p)
    return out


def _table(r, node, full, base, fields, units, extra=()):
    """One table (a stream or the anchors file) of the mapping."""
    allowed = TABLE_KEYS + ("time_unit", "time_offset") * ("t" in fields) + tuple(units) + tuple(extra)
    r.check_keys(node, full, allowed)
    t = Table()
    t.key = full
    t.paths = _paths(r, node, full, base)
    if "delimiter" in node:
        d = node["delimiter"]
        names = {"tab": "\t", "comma": ",", "semicolon": ";", "space": " ", "whitespace": None}
        if isinstance(d, str) and d in names:
            t.delimiter = names[d]
        elif isinstance(d, str) and len(d) == 1 and d not in "\"\r\n":
            t.delimiter = None if d == " " else d
        else:
            r.fail(node, full + ".delimiter", "must be one character or one of tab, comma, semicolon, space, "
                   f"whitespace (runs of blanks), got {d!r}")
    if "header" in node:
        t.header = r.boolean(node, "header", full + ".header")
    if "skip_lines" in node:
        t.skip_lines = r.integer(node, "skip_lines", full + ".skip_lines", 0)
    if "comment" in node:
        c = node["comment"]
        if c is not None and not (isinstance(c, str) and c):
            r.fail(node, full + ".comment", f"must be a text (lines starting with it are skipped) or null, got {c!r}")
        t.comment = c
    if "time_unit" in node:
        t.time_factor, t.units["time_unit"] = r.unit(node, "time_unit", full + ".time_unit", TIME_UNITS)
    if "time_offset" in node:
        t.time_offset = r.decimal(node, "time_offset", full + ".time_offset")
    for ukey, (table, default, applies) in units.items():
        factor, text = Decimal(table[default]), default
        if ukey in node:
            factor, text = r.unit(node, ukey, full + "." + ukey, table)
        t.units[ukey] = text
        for f in applies:
            t.factors[f] = factor
    for k in extra:
        if k in node:
            t.extra[k] = node[k]
    cols = r.map(node, "columns", full + ".columns", required=True)
    r.check_keys(cols, full + ".columns", tuple(fields))
    for f in cols:
        t.columns[f] = _column(r, cols, f, f"{full}.columns.{f}", t.header)
    missing = [f for f, need in fields.items() if need is None and f not in t.columns]
    if missing:
        r.fail_node(cols, full + ".columns", f"lacks {', '.join(missing)} (required: "
                    f"{', '.join(f for f, n in fields.items() if n is None)})")
    if "t" in t.columns and t.columns["t"].value is not None:
        r.fail(cols, full + ".columns.t", "must be a column, not a constant")
    for f, col in t.columns.items():   # the factor of each numeric field: unit times the column's scale
        t.scaled[f] = t.factors.get(f, Decimal(1)) * (col.scale if col.scale is not None else 1)
    return t


def _range_columns(r, t, node):
    cols = node["columns"]
    full = t.key + ".columns"
    c = t.columns
    pair = "tag_id" in c or "anchor_id" in c
    ids = "UWB_ID1" in c or "UWB_ID2" in c
    if pair and ids:
        r.fail_node(cols, full, "takes either tag_id and anchor_id, or UWB_ID1 and UWB_ID2 (with optional "
                    "type_ID1, type_ID2), not both")
    if pair and not ("tag_id" in c and "anchor_id" in c):
        r.fail_node(cols, full, "needs both tag_id and anchor_id")
    if not pair and not ("UWB_ID1" in c and "UWB_ID2" in c):
        r.fail_node(cols, full, "needs the devices: tag_id and anchor_id, or UWB_ID1 and UWB_ID2")
    if pair and ("type_ID1" in c or "type_ID2" in c):
        r.fail_node(cols, full, "type_ID1/type_ID2 go with UWB_ID1/UWB_ID2 only (tag_id, anchor_id say the types)")
    if ("type_ID1" in c) != ("type_ID2" in c):
        r.fail_node(cols, full, "needs both type_ID1 and type_ID2, or neither (then: a listed tag is T, any other "
                    "device A)")
    if "R" in c and "sigma" in c:
        r.fail_node(cols, full, "takes R (variance) or sigma (standard deviation), not both")
    for f in ("UWB_ID1", "UWB_ID2", "tag_id", "anchor_id", "type_ID1", "type_ID2", "LOS"):
        if f in c and c[f].scale is not None:
            r.fail(cols, f"{full}.{f}.scale", "is for numeric values only")


def _id_key(r, node, k, full):
    """A recording's device id used as a key of `full` (integers, also negative, or names)."""
    return canonical_id(k)


def load(path, base_override=None):
    """Reads and checks the mapping file at `path`; returns a Mapping."""
    yaml, Loader = _yaml_loader()
    try:
        with open(path, encoding="utf-8-sig") as f:
            loader = Loader(f)
            loader.name = path
            try:
                root = loader.get_single_data()
            finally:
                loader.dispose()
    except OSError as ex:
        raise MappingError(f"{path}: cannot read the mapping file ({ex.strerror or ex})")
    except yaml.YAMLError as ex:
        mark = getattr(ex, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark is not None else path
        what = " ".join(x for x in (getattr(ex, "context", None), getattr(ex, "problem", None)) if x) or str(ex)
        raise MappingError(f"{where}: not valid YAML ({what})".replace("\n", " "))
    if not isinstance(root, _Map):
        raise MappingError(f"{path}: top level must be a map (docs/formats.md, \"Importing your own CSVs\")")
    r = _Reader(path)
    r.check_keys(root, "", TOP_KEYS)
    m = Mapping(path)
    if "version" in root and r.integer(root, "version", "version") != 1:
        r.fail(root, "version", f"must be 1 (the only layout so far), got {root['version']}")
    if "description" in root:
        m.description = r.text(root, "description", "description")
    if "base" in root:
        m.base = os.path.normpath(os.path.join(m.base, os.path.expanduser(r.text(root, "base", "base"))))
    if base_override:
        m.base = os.path.abspath(base_override)

    ids = r.map(root, "ids", "ids")
    if ids is not None:
        r.check_keys(ids, "ids", ("offset", "map", "imu"))
        if "offset" in ids:
            m.id_offset = r.integer(ids, "offset", "ids.offset", 0)
        if "imu" in ids:
            m.imu_id = r.integer(ids, "imu", "ids.imu", 1)
            m.imu_id_given = ids.lines["imu"]
        idm = r.map(ids, "map", "ids.map")
        for k in idm or {}:
            m.id_map[_id_key(r, idm, k, "ids.map")] = r.integer(idm, k, f"ids.map.{k}", 1)
        targets = list(m.id_map.values())
        dup = {x for x in targets if targets.count(x) > 1}
        if dup:
            r.fail(ids, "ids.map", f"gives meshnav id {sorted(dup)[0]} to two devices")

    def device(node, k, full):
        out = map_id(m, k)
        if out is None:
            r.fail(node, f"{full}.{k}", "is neither an id >= 0 nor listed in ids.map (names and negative ids need "
                   "an entry there)")
        if out <= 0:
            r.fail(node, f"{full}.{k}", f"becomes meshnav id {out}; ids must be > 0 (set ids.offset or ids.map)")
        return out

    tags = r.map(root, "tags", "tags", required=True)
    if not tags:
        r.fail(root, "tags", "must list every tag that ranges: {id: [x, y, z]}, its position in the IMU frame [m] "
               "([0, 0, 0] when unknown)")
    for k in tags:
        _id_key(r, tags, k, "tags")
        m.tags[device(tags, k, "tags")] = r.vec3(tags, k, f"tags.{k}")
    anchors = r.map(root, "anchors", "anchors")
    for k in anchors or {}:
        _id_key(r, anchors, k, "anchors")
        a = device(anchors, k, "anchors")
        if a in m.tags:
            r.fail(anchors, f"anchors.{k}", f"meshnav id {a} is also a tag")
        m.anchors[a] = r.vec3(anchors, k, f"anchors.{k}")
    af = r.map(root, "anchors_file", "anchors_file")
    if af is not None:
        m.anchors_file = _table(r, af, "anchors_file", m.base, {f: None for f in ANCHORS_FILE_FIELDS},
                                {"unit": (LENGTH_UNITS, "m", ("x", "y", "z"))})
        if m.anchors_file.columns["id"].value is not None:
            r.fail(af["columns"], "anchors_file.columns.id", "must be a column, not a constant")
    noise = r.map(root, "noise", "noise")
    for k in noise or {}:
        if k not in NOISE_KEYS:
            raise MappingError(f"{path}:{noise.lines[k]}: unknown key 'noise.{k}' (known here: {', '.join(NOISE_KEYS)})")
        v = r.number(noise, k, f"noise.{k}")
        if not (v >= 0 if NOISE_KEYS[k] else v > 0):
            r.fail(noise, f"noise.{k}", f"must be {'>= 0' if NOISE_KEYS[k] else '> 0'}, got {v}")
        m.noise[k] = v

    for kind, spec in STREAMS.items():
        v = root.get(kind)
        if v is None:
            if kind == "ranges":
                r.fail(root, "ranges", "is required: the UWB ranges' CSV (docs/formats.md, \"Importing your own CSVs\")")
            continue
        nodes = v if isinstance(v, list) else [v]
        if not nodes:
            r.fail(root, kind, "is an empty list")
        tables = []
        for i, node in enumerate(nodes):
            full = kind if not isinstance(v, list) else f"{kind}[{i}]"
            if not isinstance(node, _Map):
                r.fail(root, full, f"must be a map (path, columns, ...), got {node!r}")
            t = _table(r, node, full, m.base, spec["fields"], spec["units"], spec.get("extra", ()))
            if kind == "ranges":
                _range_columns(r, t, node)
            if kind == "groundtruth":
                if "frame" in t.extra:
                    t.extra["frame"] = r.text(node, "frame", full + ".frame")
                if "align_required" in t.extra:
                    t.extra["align_required"] = r.boolean(node, "align_required", full + ".align_required")
            tables.append(t)
        if kind == "groundtruth" and len({(x.extra.get("frame"), x.extra.get("align_required")) for x in tables}) > 1:
            r.fail(root, kind, "parts disagree on frame or align_required")
        m.streams[kind] = tables
    return m
