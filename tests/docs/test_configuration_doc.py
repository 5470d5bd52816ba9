"""docs/configuration.md lists every estimator option and every model parameter with its default.

Runs `meshnav_run --print-config` (the 57 options) and `--print-model-parameters` (the model
parameters fixed in code) and checks the doc's tables against them: every key has a row
"| `full.key` | value |" with the printed value, options in the section "Estimator options",
model parameters in "Model parameters", each once and in the table under "### <YAML section>"
("### Top level" for keys without a section), and those sections have no row for a key that
neither list holds. Only these two sections are checked (the setup.yaml and calibrator tables
elsewhere have keys of their own).

Usage: test_configuration_doc.py [MESHNAV_RUN] [unittest options]; without the argument the binary
is $MESHNAV_RUN_BIN, else build/bin/meshnav_run of this checkout. The doc is
$MESHNAV_SOURCE_DIR/docs/configuration.md, else the one of this checkout.
"""

import os
import re
import subprocess
import sys
import unittest

ROOT = os.path.abspath(os.environ.get("MESHNAV_SOURCE_DIR",
                                      os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")))
DOC = os.path.join(ROOT, "docs", "configuration.md")
RUN_BIN = os.environ.get("MESHNAV_RUN_BIN", os.path.join(ROOT, "build", "bin", "meshnav_run"))

OPTIONS_HEADING = "## Estimator options"
PARAMETERS_HEADING = "## Model parameters"


def parse_listing(text):
    """{dotted key: value} of a `--print-config`-style listing: "key: value  # comment" lines,
    a section header "name:" (no value) followed by its keys indented two spaces."""
    values = {}
    section = None
    for number, line in enumerate(text.splitlines(), 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        match = re.fullmatch(r"( {2})?([A-Za-z0-9_]+):(?: +(.*?))?", line.split("  #", 1)[0].rstrip())
        if not match:
            raise ValueError(f"line {number}: not 'key: value', 'section:' or '  key: value': {line!r}")
        indented, key, value = match.group(1) is not None, match.group(2), match.group(3)
        if value is None:  # a section header
            if indented:
                raise ValueError(f"line {number}: a section inside a section: {line!r}")
            section = key
            continue
        if indented and section is None:
            raise ValueError(f"line {number}: an indented key outside a section: {line!r}")
        if not indented:
            section = None
        full = f"{section}.{key}" if indented else key
        if full in values:
            raise ValueError(f"line {number}: {full} listed twice")
        values[full] = value
    return values


def print_listing(flag):
    if not os.access(RUN_BIN, os.X_OK):
        raise AssertionError(f"no meshnav_run at {RUN_BIN}: give its path as the first argument or in MESHNAV_RUN_BIN")
    p = subprocess.run([RUN_BIN, flag], capture_output=True, text=True, timeout=60)
    if p.returncode != 0:
        raise AssertionError(f"{RUN_BIN} {flag} exited with {p.returncode}: {p.stderr.strip()}")
    return parse_listing(p.stdout)


def section_rows(doc, heading):
    """[(line number, key, value, table heading)] of the key tables (first header cell "key") in
    the level-2 section whose heading starts with `heading`, up to the next level-2 heading; the
    table heading is the text of the "### " heading above the table."""
    lines = doc.splitlines()
    start = next((i for i, l in enumerate(lines) if l.startswith(heading)), None)
    if start is None:
        raise AssertionError(f"{DOC}: no section '{heading}'")
    rows = []
    header = None  # first header cell of the current table
    table_heading = None
    for i in range(start + 1, len(lines)):
        line = lines[i]
        if line.startswith("## "):
            break
        if line.startswith("### "):
            table_heading = line[4:].strip()
        if not line.startswith("|"):
            header = None
            continue
        # Cells split at "|" but not at "\|" (a pipe inside a cell, as in "\|g\|").
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip().strip("|"))]
        if header is None:
            header = cells[0]
            continue
        if set(cells[0]) <= set("-: "):  # the |---| line
            continue
        if header != "key":
            continue
        key = re.fullmatch(r"`([^`]+)`", cells[0])
        rows.append((i + 1, key.group(1) if key else cells[0], cells[1] if len(cells) > 1 else "", table_heading))
    return rows


def problems(doc, options, parameters):
    """What the doc gets wrong against the two listings, one line each (empty: in sync)."""
    found = []
    for heading, listed, other, what in ((OPTIONS_HEADING, options, parameters, "option"),
                                         (PARAMETERS_HEADING, parameters, options, "model parameter")):
        try:
            rows = section_rows(doc, heading)
        except AssertionError as e:
            found.append(str(e))
            continue
        seen = {}
        for line, key, value, table in rows:
            if key in seen:
                found.append(f"{DOC}:{line}: `{key}` has a second row (first at line {seen[key]})")
                continue
            seen[key] = line
            if key in listed:
                if value != listed[key]:
                    found.append(f"{DOC}:{line}: `{key}` is {value!r}, meshnav_run prints {listed[key]!r}")
                yaml_section = key.split(".")[0] if "." in key else "Top level"
                if table != yaml_section:
                    found.append(f"{DOC}:{line}: `{key}` is in the table under '### {table}', not '### {yaml_section}'")
            elif key in other:
                found.append(f"{DOC}:{line}: `{key}` is not an {what} but "
                             f"{'a model parameter' if what == 'option' else 'an option'}: its row belongs "
                             f"in the other section")
            else:
                found.append(f"{DOC}:{line}: `{key}` is neither an option nor a model parameter of meshnav_run")
        for key, value in listed.items():
            if key not in seen:
                found.append(f"{DOC}: no row '| `{key}` | {value} |' in section '{heading}' ({what})")
    return found


class ConfigurationDoc(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.options = print_listing("--print-config")
        cls.parameters = print_listing("--print-model-parameters")
        with open(DOC, encoding="utf-8") as f:
            cls.doc = f.read()

    def test_the_listings_are_read(self):
        # Not vacuous: both listings parse into many keys, with none in both.
        self.assertGreater(len(self.options), 40)
        self.assertGreater(len(self.parameters), 40)
        for key in ("profile", "strategy", "uwb.sigma_range_m", "fixed_lag.lag_s"):
            self.assertIn(key, self.options)
        for key in ("joseph_form", "process_noise.max_grow", "time.rebase_after", "refine.rerun_mode"):
            self.assertIn(key, self.parameters)
        self.assertEqual(sorted(set(self.options) & set(self.parameters)), [])

    def test_every_option_and_model_parameter_has_its_row_and_no_other_key_does(self):
        found = problems(self.doc, self.options, self.parameters)
        if found:
            self.fail(f"docs/configuration.md is out of step with meshnav_run ({len(found)}):\n" + "\n".join(found))
        print(f"\n{DOC}: {len(self.options)} options and {len(self.parameters)} model parameters, "
              f"each with its row and default", file=sys.stderr)

    def test_the_check_fails_on_a_missing_a_wrong_or_an_unknown_row(self):
        # The same check on edited copies of the doc: it must catch each edit.
        key, value = "uwb.sigma_range_m", self.options["uwb.sigma_range_m"]
        row = f"| `{key}` | {value} |"
        self.assertIn(row, self.doc)
        without = "\n".join(l for l in self.doc.splitlines() if not l.startswith(row))
        self.assertTrue(any(f"no row '| `{key}`" in p for p in problems(without, self.options, self.parameters)))
        wrong = self.doc.replace(row, f"| `{key}` | {value}1 |")
        self.assertTrue(any(f"meshnav_run prints {value!r}" in p
                            for p in problems(wrong, self.options, self.parameters)))
        lines = self.doc.splitlines()
        at = next(i for i, l in enumerate(lines) if l.startswith(row))
        unknown = "\n".join(lines[:at + 1] + ["| `uwb.sigma_rnage_m` | 0.15 | m | a typo |"] + lines[at + 1:])
        self.assertTrue(any("`uwb.sigma_rnage_m` is neither" in p
                            for p in problems(unknown, self.options, self.parameters)))


if __name__ == "__main__":
    if len(sys.argv) > 1 and not sys.argv[1].startswith("-"):
        RUN_BIN = sys.argv.pop(1)
    unittest.main()
