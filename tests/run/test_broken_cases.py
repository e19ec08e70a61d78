"""The broken-case corpus: every file in tests/cases/broken gives exit status 2 and a message
containing each ``# expect:`` line of its header (the key path, the bad value, what is
allowed), never a traceback. Also: missing file, empty file, directory, unreadable input."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from thermodem.cli import app

BROKEN = sorted((Path(__file__).parents[1] / "cases" / "broken").glob("*.yaml"))


def expectations(path: Path) -> list[str]:
    out = []
    for line in path.read_text().splitlines():
        if not line.startswith("# expect:"):
            break
        out.append(line.removeprefix("# expect:").strip())
    return out


def test_the_corpus_is_large_enough() -> None:
    assert len(BROKEN) >= 20
    assert all(expectations(p) for p in BROKEN)


@pytest.mark.parametrize("path", BROKEN, ids=[p.stem for p in BROKEN])
def test_broken_case(path: Path) -> None:
    result = CliRunner().invoke(app, ["validate", str(path)])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    # (a case refused while the engine is built comes after the note that kernels compile,
    # when Numba's cache is cold)
    output = "".join(
        line for line in result.output.splitlines(True) if not line.startswith("# compiling")
    )
    assert output.startswith("error: ")
    for expected in expectations(path):
        assert expected in output, f"{expected!r} not in:\n{output}"


def test_broken_case_refused_by_run_too(tmp_path: Path) -> None:
    path = next(p for p in BROKEN if p.stem == "missing_thermal_conductivity")
    result = CliRunner().invoke(app, ["run", str(path), "--output", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert "materials.glass.thermal_conductivity" in result.output


def _file(directory: Path, name: str, content: bytes) -> Path:
    path = directory / name
    path.write_bytes(content)
    return path


def _big_vector(directory: Path) -> Path:
    """A case whose gravity is a 50 MB vector (refused by its size, before YAML parses it)."""
    path = directory / "big.yaml"
    with path.open("w") as f:
        f.write("simulation: {time_step: 1.0e-5, end_time: 0.001, gravity: [")
        chunk = "0.0, " * 100_000
        while f.tell() < 50_000_000:
            f.write(chunk)
        f.write("0.0]}\n")
    return path


def test_aliases_within_the_limit_still_work(tmp_path: Path) -> None:
    """Anchors and aliases that repeat a material are fine; only the expansion is bounded."""
    from thermodem.config.load import load_case

    path = _file(
        tmp_path,
        "alias.yaml",
        b"simulation: {time_step: 1.0e-5, end_time: 0.001}\n"
        b"domain: {lower: [0, 0, 0], upper: [0.01, 0.01, 0.01]}\n"
        b"materials:\n  glass: &g {density: 2500, youngs_modulus: 1.0e7, poisson_ratio: 0.3}\n"
        b"  steel: *g\n",
    )
    case = load_case(path)
    assert case.materials["steel"] == case.materials["glass"]


def test_merge_keys_are_read_and_only_true_duplicates_refused(tmp_path: Path) -> None:
    """``<<: *name`` (YAML's merge key) was refused as 'could not determine a constructor for
    the tag ...merge' by the duplicate-key loader; a merged key given again beside ``<<`` is
    an override, a key written twice in one mapping is still a duplicate."""
    from thermodem.config.load import load_case

    head = (
        b"simulation: {time_step: 1.0e-5, end_time: 0.001}\n"
        b"domain: {lower: [0, 0, 0], upper: [0.01, 0.01, 0.01]}\n"
        b"materials:\n  glass: &g {density: 2500, youngs_modulus: 1.0e7, poisson_ratio: 0.3}\n"
    )
    case = load_case(_file(tmp_path, "merge.yaml", head + b"  steel: {<<: *g, density: 7800}\n"))
    assert case.materials["steel"].density == 7800.0
    assert case.materials["steel"].youngs_modulus == 1.0e7
    twice = _file(tmp_path, "twice.yaml", head + b"  steel: {<<: *g, density: 1, density: 2}\n")
    result = CliRunner().invoke(app, ["validate", str(twice)])
    assert result.exit_code == 2
    assert "line 5, column 31: duplicate key 'density' (first at line 5)" in result.output


@pytest.mark.parametrize(
    ("make", "expected"),
    [
        (lambda d: d / "missing.yaml", "does not exist"),
        (lambda d: d, "is a directory"),
        (lambda d: _file(d, "empty.yaml", b""), "is empty"),
        (lambda d: _file(d, "blank.yaml", b"\n  \n# only a comment\n"), "is empty"),
        (lambda d: _file(d, "binary.yaml", b"\xff\xfe\x00x"), "not UTF-8"),
        (lambda d: _big_vector(d), "is 50 MB; a case file may have at most 5 MB"),
    ],
    ids=["missing", "directory", "empty", "blank", "binary", "50MB-vector"],
)
def test_bad_files_give_one_line(tmp_path: Path, make, expected: str) -> None:  # noqa: ANN001
    path = make(tmp_path)
    result = CliRunner().invoke(app, ["validate", str(path)])
    assert result.exit_code == 2
    assert expected in result.output
    assert len(result.output.strip().splitlines()) == 1, result.output


UNION_HEAD = (
    "simulation: {time_step: 1.0e-5, end_time: 0.001}\n"
    "domain: {lower: [0, 0, 0], upper: [0.01, 0.01, 0.01]}\n"
    "materials:\n  glass: {density: 2500, youngs_modulus: 1.0e7, poisson_ratio: 0.3}\n"
)
LATTICE = (
    "insertion:\n  - {kind: lattice, material: glass, distribution: {kind: mono, radius: 0.001},"
    " lower: [0, 0, 0], upper: [0.006, 0.006, 0.006], spacing: %s}\n"
)


@pytest.mark.parametrize(
    ("body", "expected"),
    [
        (LATTICE % "-1", "insertion.0.spacing: must be greater than 0 (got -1), or a list of "
         "three such values"),
        (LATTICE % "abc", "insertion.0.spacing: should be a number or a list of three numbers "
         "(got 'abc')"),
        (LATTICE % "[0.002, 0, 0.002]", "insertion.0.spacing.1: Input should be greater than 0 "
         "(got 0)"),
        ("walls:\n  - {kind: plane, point: [0, 0, 0], normal: [0, 0, 1], material: glass, "
         "thermal: {kind: fixed, temperature: {a: 1}}}\n",
         "walls.0.thermal.temperature: should be a number, a list of rows of two numbers or a "
         "string (got {'a': 1})"),
    ],
    ids=["spacing-negative", "spacing-string", "spacing-list-item", "temperature-mapping"],
)  # fmt: skip
def test_a_value_for_a_union_gets_one_line_without_type_names(
    tmp_path: Path, body: str, expected: str
) -> None:
    """A number-or-list key given a bad value printed one line per member of the union,
    named by pydantic's types (insertion.0.spacing.constrained-float: ... and
    insertion.0.spacing.tuple[constrained-float, ...]: should be a list of values)."""
    path = _file(tmp_path, "union.yaml", (UNION_HEAD + body).encode())
    result = CliRunner().invoke(app, ["validate", str(path)])
    assert result.exit_code == 2, result.output
    lines = result.output.splitlines()
    assert lines[1:] == [expected], result.output
