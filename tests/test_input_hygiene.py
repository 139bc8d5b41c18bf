"""Input hygiene (issue 20): YAML numbers in the sense both YAML 1.1 and 1.2 agree on, finite
numbers on the command line, models built from Python validated exactly as a file is, and the
words of the messages (what the user wrote, articles, certified or not).
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml
from cli_helpers import ok, one_line, run_cli
from conftest import CONFIGS, M1_YAML, M2_YAML

from fivebar_cli.io.schema import ConfigError, read_yaml, yaml12
from fivebar_cli.mechanisms.fivebar.model import FiveBar
from fivebar_cli.mechanisms.registry import load_config
from fivebar_cli.mechanisms.rpr2.model import Rpr2

ALL_CONFIGS = sorted(CONFIGS.rglob("*.yaml"))


@pytest.mark.parametrize("path", ALL_CONFIGS, ids=lambda p: p.relative_to(CONFIGS).as_posix())
def test_every_config_reads_as_plain_pyyaml_reads_it(path):
    assert read_yaml(path) == yaml.safe_load(path.read_text())


# (value as written, YAML 1.1's reading, YAML 1.2's reading): refused, with the field named
AMBIGUOUS = [
    ("1:2", "the number 62", "the text '1:2'"),        # base 60
    ("1_000", "the number 1000", "the text '1_000'"),  # digit separators
    ("017", "the number 15", "the number 17"),         # octal in 1.1 only
    ("0o17", "the text '0o17'", "the number 15"),      # octal in 1.2 only
    ("0b101", "the number 5", "the text '0b101'"),
    ("yes", "the boolean true", "the text 'yes'"),
    ("off", "the boolean false", "the text 'off'"),
    ("1e-3", "the text '1e-3'", "the number 0.001"),   # an exponent without a point or a sign
    ("1.0e5", "the text '1.0e5'", "the number 100000.0"),
    ("2026-01-02", "a date", "the text '2026-01-02'"),
]


@pytest.mark.parametrize("text, old, new", AMBIGUOUS)
def test_scalars_read_differently_by_yaml_1_1_and_1_2_are_refused_with_the_field(tmp_path, text, old, new):
    config = tmp_path / "m.yaml"
    config.write_text(f"name: M\ntype: fivebar\nlengths: {{L0: 9, L1: {text}, L2: 5, L3: 5, L4: 8}}\n")
    r = run_cli("workspace", config, "--depth", 2, "-o", "out", cwd=tmp_path)
    one_line(r, 2, f"m.yaml: lengths.L1: {text} is {old} in YAML 1.1 but {new} in YAML 1.2")
    assert not (tmp_path / "out").exists()


def test_the_yaml_1_2_readings_and_what_still_reads():
    assert [yaml12(t) for t in ("8", "-8", "+8", "8.", ".5", "1.0e-3", "0x1F", "true", "~", "M1")] == \
        [8, -8, 8, 8.0, 0.5, 0.001, 31, True, None, "M1"]
    assert math.isinf(yaml12(".inf")) and math.isnan(yaml12(".nan"))


@pytest.mark.parametrize("body, field, needle", [
    ("lengths: {L0: 9, L1: , L2: 5, L3: 5, L4: 8}", "lengths.L1", "expected a number, got an empty value"),
    ("lengths: {L0: 9, L1: .inf, L2: 5, L3: 5, L4: 8}", "lengths.L1", "must be finite"),
    ("lengths: {L0: 9, L1: 8, L2: 5, L3: 5, L4: 8}\nyes: 1", "yes", "the key yes is the boolean true in YAML 1.1"),
])
def test_messages_say_what_was_written(tmp_path, body, field, needle):
    (tmp_path / "m.yaml").write_text(f"name: M\ntype: fivebar\n{body}\n")
    one_line(run_cli("workspace", tmp_path / "m.yaml", "-o", tmp_path / "o"), 2, f"{field}: {needle}")


# ---------------------------------------------------------------- models from Python: one validation


@pytest.mark.parametrize("lengths, field", [
    ((math.nan, 8.0, 5.0, 5.0, 8.0), "lengths.L0"),
    ((9.0, -8.0, 5.0, 5.0, 8.0), "lengths.L1"),
    ((9.0, 8.0, 5.0, math.inf, 8.0), "lengths.L3"),
    ((30.0, 8.0, 5.0, 5.0, 8.0), "lengths"),  # the loop never closes
    ((9.0, 8.0, 5.0, 5.0, 1e60), "lengths.L4"),
])
def test_a_five_bar_from_python_is_checked_as_its_yaml_is(tmp_path, lengths, field):
    """The same field and message as the YAML file with these lengths."""
    config = tmp_path / "m.yaml"
    config.write_text("name: M\ntype: fivebar\nlengths: {"
                      + ", ".join(f"L{k}: {v!r}".replace("nan", ".nan").replace("inf", ".inf").replace("e+60", ".0e+60")
                                  for k, v in enumerate(lengths)) + "}\n")
    with pytest.raises(ConfigError) as from_file:
        load_config(config)
    with pytest.raises(ConfigError) as from_python:
        FiveBar("M", *lengths)
    assert from_python.value.field == from_file.value.field == field
    assert from_python.value.message == from_file.value.message
    assert isinstance(from_python.value, ValueError) and str(from_python.value).startswith("FiveBar(...): ")


def test_models_from_python_other_kinds_and_a_bad_name():
    with pytest.raises(ConfigError, match=r"Rpr2\(\.\.\.\): legs.rho_max: must be finite"):
        Rpr2("r", 8.0, 3.0, math.nan)
    with pytest.raises(ConfigError, match=r"Rpr2\(\.\.\.\): legs: rho_min \(15.0\) must be smaller"):
        Rpr2("r", 8.0, 15.0, 3.0)
    with pytest.raises(ConfigError, match="name: 'a/b' is not usable as a folder name"):
        FiveBar("a/b", 9, 8, 5, 5, 8)
    import dataclasses
    general = load_config(CONFIGS / "rpr3-general.yaml")
    with pytest.raises(ConfigError, match=r"Rpr3\(\.\.\.\): legs.rho_min\[0\]: must not be negative"):
        dataclasses.replace(general, rho_min=(-1.0, 10.0, 10.0))
    table1 = load_config(CONFIGS / "rpr3-table1.yaml")
    with pytest.raises(ConfigError, match=r"phi_range\[0\]: must be finite"):
        dataclasses.replace(table1, phi_range=(math.nan, 165.0))
    assert dataclasses.replace(general, name="g2").name == "g2"  # a valid model is built as before
    assert FiveBar("M1", 9, 8, 5, 5, 8).widened(0.05).bounds[0] == (8.95, 9.05)


# ---------------------------------------------------------------- the command line


@pytest.mark.parametrize("args, option", [
    (["workspace", M1_YAML, "--tolerance", "nan"], "--tolerance"),
    (["aspects", M1_YAML, "--tolerance", "inf"], "--tolerance"),
    (["atlas", CONFIGS / "atlas-l1-l3.yaml", "--tolerance", "-inf"], "--tolerance"),
    (["rpr3", "sweep", CONFIGS / "rpr3-equilateral.yaml", "--over", "rho_min", "--range", "0", "nan"], "--range"),
    (["rpr3", "sweep", CONFIGS / "rpr3-equilateral.yaml", "--over", "t2", "--angles", "30,inf"], "--angles"),
    (["tolerance", M1_YAML, "--tolerances", "0,nan"], "--tolerances"),
])
def test_command_line_numbers_must_be_finite(tmp_path, args, option):
    one_line(run_cli(*args, "-o", "out", cwd=tmp_path), 2, option)
    assert not (tmp_path / "out").exists()


def test_counts_say_whether_they_are_certified_and_kinds_take_their_article(tmp_path):
    r = ok(run_cli("tolerance", M1_YAML, "--tolerances", "0", "--depth", 6, "-o", "out", "--no-plot", cwd=tmp_path))
    first = r.stdout.splitlines()[0]
    assert "not certified at this depth" in first and "between" in first, first  # M1 has 10, depth 6 cannot tell
    r = ok(run_cli("tolerance", M2_YAML, "--tolerances", "0", "--depth", 9, "-o", "out2", "--no-plot", cwd=tmp_path))
    assert "(10 nominal generalized aspects, certified)" in r.stdout.splitlines()[0]
    one_line(run_cli("jointspace", CONFIGS / "rpr3-general.yaml", "-o", "o", cwd=tmp_path), 2,
             "an rpr3 has no jointspace to pave")
    one_line(run_cli("workspace", CONFIGS / "rpr2.yaml", "--tolerance", 0.1, "-o", "o", cwd=tmp_path), 2,
             "an rpr2 has no interval lengths")
    one_line(run_cli("rpr3", "area", M1_YAML, "-o", "o", cwd=tmp_path), 2, "expected an rpr3 ('type: rpr3') here, got 'fivebar'")
