"""Legal names never break the end of a run (defect 5): every user string that reaches rich, matplotlib
or XML is escaped by one helper per target (``reports.format.rich_text``, ``plots.common.mpl_text``,
``io.fmu.xml_text``/``xml_attr``)."""

from __future__ import annotations

import os
import re
import shutil
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import pytest
from rich.console import Console

from conftest import TABLE_C1
from tcsim.io import fmu as fmu_io
from tcsim.models.converter import load_converter
from tcsim.models.vehicle import load_vehicle
from tcsim.plots.common import mpl_text, plt
from tcsim.reports.format import rich_text

BUNDLED = Path(load_converter("li-sunden-2016").path)


def assert_ok(r) -> None:
    assert r.code == 0, (r.code, r.stdout, r.stderr)
    assert "Traceback" not in r.stdout + r.stderr and "Error" not in r.stderr, r.stderr


def test_out_with_rich_markup_is_printed_as_it_is(cli, tmp_path):
    """`--out 'o[/]'` made the success message raise MarkupError after every file was written."""
    r = cli("characterise", "li-sunden-2016", "--out", "o[/]", cwd=tmp_path)
    assert_ok(r)
    assert "written to o[/]/characteristic.csv" in r.stdout
    assert (tmp_path / "o[" / "]" / "characteristic.csv").is_file()


def test_vehicle_name_with_rich_markup(cli, tmp_path):
    text = Path(load_vehicle(None).path).read_text()
    text = text.replace('name = "midsize-awd-8at"', 'name = "car [/] [bold]x"', 1)
    text = text.replace('converter = "li-sunden-2016-fitted"', 'converter = "li-sunden-2016"', 1)
    (tmp_path / "car.toml").write_text(text)
    r = cli("launch", tmp_path / "car.toml", "--model", "table", "--out", tmp_path / "o")
    assert_ok(r)
    assert "launch of car [/] [bold]x" in r.stdout


@pytest.mark.parametrize("name", ["a$b$.csv", "a$x^$.csv"])
def test_converter_file_name_with_dollars(cli, tmp_path, name):
    """A `$…$` in a table's file name (the converter's name) went into the matplotlib title as mathtext
    (`a$x^$`: exit 1 with a multi-line mathtext error)."""
    shutil.copy(TABLE_C1, tmp_path / name)
    assert_ok(cli("characterise", tmp_path / name, "--out", tmp_path / "o"))


def test_converter_name_with_mathtext(cli, tmp_path):
    text = BUNDLED.read_text().replace('name = "li-sunden-2016"', r'name = "$x$ $\\frac{$"', 1)
    (tmp_path / "c.toml").write_text(text)
    assert_ok(cli("characterise", tmp_path / "c.toml", "--out", tmp_path / "o"))


@pytest.mark.skipif(os.name != "posix" or os.uname().sysname == "Darwin", reason="needs byte file names")
def test_non_utf8_file_name(cli, tmp_path):
    name = os.fsdecode(b"conv\xff.csv")
    shutil.copy(TABLE_C1, tmp_path / name)
    assert_ok(cli("characterise", tmp_path / name, "--out", tmp_path / "o"))


def test_mpl_text_draws_every_character_as_given(tmp_path):
    fig, ax = plt.subplots()
    for text in ("$x$", r"a\$b$", "$\\frac{", "tab\there", os.fsdecode(b"\xff"), "bell\x07"):
        ax.set_title(mpl_text(text))
        fig.savefig(tmp_path / "t.png")  # raised for mathtext, surrogates (and drew controls as boxes)
    plt.close(fig)
    assert mpl_text("$x$ costs $5") == r"\$x\$ costs \$5"
    assert mpl_text("a\x01b\tc\nd") == r"a\x01b\tc\nd"


def test_rich_text_is_shown_as_it_is():
    console = Console(record=True, width=200)
    for text in ("o[/]", "[bold]x[/bold]", "trailing \\", "[link=x]y"):
        console.print(rich_text(text))
    assert console.export_text().splitlines() == ["o[/]", "[bold]x[/bold]", "trailing \\", "[link=x]y"]


def test_xml_text_replaces_what_xml_forbids():
    assert fmu_io.xml_text("a\x01b\udcffc\td") == "a\\x01b\\udcffc\td"
    attr = fmu_io.xml_attr('x\x1f<&"y')
    assert ElementTree.fromstring(f"<a b={attr}/>").get("b") == 'x\\x1f<&"y'


def test_fmu_of_a_converter_file_with_a_control_character(library_env, cli, tmp_path):
    """A control character in the converter's file name went unescaped into modelDescription.xml."""
    fmpy = pytest.importorskip("fmpy")
    source = tmp_path / "conv\x01.toml"
    shutil.copy(BUNDLED, source)
    out = tmp_path / "c.fmu"
    assert_ok(cli("export-fmu", source, "--model", "table", "--out", out))
    with zipfile.ZipFile(out) as zf:
        root = ElementTree.fromstring(zf.read("modelDescription.xml"))
    assert "conv\\x01" in root.get("modelName", "")
    assert pytest.importorskip("fmpy.validation").validate_fmu(str(out)) == []
    fmpy.read_model_description(str(out))


@pytest.fixture
def library_env(fmu_library, monkeypatch):
    monkeypatch.setenv(fmu_io.LIBRARY_ENV, str(fmu_library))
    return fmu_library


def test_no_markup_in_the_error_line_either(cli, tmp_path):
    r = cli("characterise", tmp_path / "no[/]such.csv", "--out", tmp_path / "o")
    assert r.code == 2 and re.search(r"no\[/\]such\.csv", r.stderr), r.stderr
