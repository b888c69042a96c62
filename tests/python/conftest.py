"""Fixtures of the Python module's tests: the module built beside them, the real command-line tool (whose
answers the module's must equal), the bundled sample meshes, a small database built once per run, and the
folder of real meshes where there is one.

ctest runs these with PYTHONPATH, SHAPEDB_CLI, SHAPEDB_SOURCE_DIR and SHAPEDB_REAL_MESHES set
(tests/CMakeLists.txt)."""

import json
import os
import pathlib
import subprocess

import pytest

import shapedb

SOURCE_DIR = pathlib.Path(os.environ.get("SHAPEDB_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
SAMPLES = SOURCE_DIR / "data" / "samples"


@pytest.fixture(scope="session")
def cli_path():
    """The built shapedb tool."""
    tool = os.environ.get("SHAPEDB_CLI")
    if not tool or not os.path.exists(tool):
        pytest.skip("SHAPEDB_CLI does not name the built shapedb tool (ctest sets it)")
    return tool


@pytest.fixture(scope="session")
def cli(cli_path):
    """Runs the shapedb tool with the given arguments and returns its parsed --json output."""

    def run(*args):
        done = subprocess.run([cli_path, *map(str, args), "--json"], capture_output=True, text=True, check=False)
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout)

    return run


@pytest.fixture(scope="session")
def samples():
    return SAMPLES


@pytest.fixture(scope="session")
def database(tmp_path_factory):
    """A 24-entry database of four families (seconds to build), as a path."""
    path = tmp_path_factory.mktemp("db") / "small.db"
    report = shapedb.build(str(path), entries=24, families="box,ellipsoid,capsule,fragment", modes=8)
    assert report["built"] == 24 and report["failed"] == 0
    return path


@pytest.fixture(scope="session")
def real_meshes():
    folder = os.environ.get("SHAPEDB_REAL_MESHES", "")
    files = sorted(
        p for p in pathlib.Path(folder).rglob("*") if p.suffix.lower() in (".obj", ".ply", ".stl", ".off")
    ) if folder and os.path.isdir(folder) else []
    if not files:
        pytest.skip(f"no real meshes in '{folder}' (set SHAPEDB_REAL_MESHES to a folder of meshes)")
    return files
