"""The Python module against the library: every function on real files, its numbers equal to the command
line tool's (the same C++ run as a subprocess) bit for bit where the computation is the same; bad input
raising shapedb's message; arrays outliving what made them."""

import gc
import subprocess
import sys
import threading

import numpy as np
import pytest

import shapedb

from conftest import SOURCE_DIR


def load(path):
    return shapedb.load_mesh(str(path))


# ---- meshes, mass properties, frames, descriptors --------------------------------------------------------


@pytest.mark.parametrize("name", ["soap", "egg", "hex-rod", "doorstop", "pebble"])
def test_mass_properties_equal_the_tools_bit_for_bit(cli, samples, name):
    path = samples / f"{name}.obj"
    vertices, faces = load(path)
    assert vertices.dtype == np.float64 and vertices.shape[1] == 3 and vertices.flags.c_contiguous
    assert faces.dtype == np.int64 and faces.shape[1] == 3
    assert faces.min() >= 0 and faces.max() < len(vertices)

    tool = cli("inspect", path)
    mine = shapedb.mass_properties(vertices, faces, density=tool["density"])
    assert mine["volume"] == tool["volume"]
    assert mine["mass"] == tool["mass"]
    assert mine["area"] == tool["area"]
    np.testing.assert_array_equal(mine["center_of_mass"], tool["center_of_mass"])
    np.testing.assert_array_equal(mine["inertia"], tool["inertia"])
    assert not mine["is_approximate"]

    # The tool normalizes at the material's density, the module at unit density: the same moments to the
    # last bits of the largest (an eigensolver's round-off is relative to the matrix's norm, so a rod's
    # small moment about its axis may differ by a few units in its own last place).
    frame = shapedb.normalize(vertices, faces)
    largest = max(tool["canonical_moments"])
    np.testing.assert_allclose(
        frame["canonical_moments"], tool["canonical_moments"], rtol=0, atol=1e-14 * largest
    )
    # The frame carries the mesh to unit volume about the origin.
    canonical = vertices @ frame["canonical_from_mesh"][:3, :3].T + frame["canonical_from_mesh"][:3, 3]
    moved = shapedb.mass_properties(canonical, faces)
    assert moved["volume"] == pytest.approx(1.0, rel=1e-12)
    np.testing.assert_allclose(moved["center_of_mass"], 0.0, atol=1e-12)
    np.testing.assert_allclose(frame["mesh_from_canonical"] @ frame["canonical_from_mesh"], np.eye(4), atol=1e-12)


def test_describe_gives_the_tools_cells_and_centroids(cli, samples):
    # The pebble's principal axes are well separated: its frame, hence its grid, does not hang on the last
    # bit of its moments (the tool normalizes at the material's density, the module at unit density).
    path = samples / "pebble.obj"
    vertices, faces = load(path)
    tool = cli("describe", path)
    mine = shapedb.describe(vertices, faces)
    assert mine["kind"] == "centroid-voxel" and mine["grid_size"] == tool["grid"] == 10
    np.testing.assert_array_equal(mine["cells"], np.flatnonzero(tool["occupancy"]))
    assert mine["cell_size"] == pytest.approx(tool["cell_size"], rel=1e-14)
    np.testing.assert_allclose(mine["moments"], tool["moments"], rtol=1e-14)
    # Centroids: the module gives them in the cell's own unit cube, the tool in the canonical frame.
    n, h, cells = mine["grid_size"], mine["cell_size"], mine["cells"]
    ijk = np.stack([cells % n, (cells // n) % n, cells // (n * n)], axis=1)
    assert ((mine["centroids"] >= 0.0) & (mine["centroids"] <= 1.0)).all()
    canonical = (ijk + mine["centroids"] - n / 2) * h
    np.testing.assert_allclose(canonical, [c for c in tool["centroids"] if c], atol=1e-12)
    assert mine["weights"].shape == cells.shape and (mine["weights"] > 0).all()

    moment = shapedb.describe(vertices, faces, kind="moment")
    np.testing.assert_array_equal(moment["moments"], mine["moments"])
    assert len(moment["cells"]) == 0


def test_load_mesh_reads_every_real_mesh_as_the_tool_does(cli, real_meshes):
    for path in real_meshes:
        tool = cli("inspect", path)
        vertices, faces = load(path)
        assert len(faces) == tool["topology"]["triangles"], path
        mine = shapedb.mass_properties(vertices, faces, density=tool["density"], approximate=tool["approximate"])
        assert mine["volume"] == tool["volume"], path
        np.testing.assert_array_equal(mine["inertia"], tool["inertia"], err_msg=str(path))


# ---- the database ----------------------------------------------------------------------------------------


def check_same_answer(mine, tool):
    """A QueryResult against the tool's JSON for the same query."""
    assert [m.name for m in mine.matches] == [m["name"] for m in tool["matches"]]
    assert [m.distance for m in mine.matches] == [m["distance"] for m in tool["matches"]]
    assert mine.answered == tool["answered"]
    physics = mine.physics
    np.testing.assert_array_equal(physics["frequencies"], tool["physics"]["frequencies_hz"])
    np.testing.assert_array_equal(physics["damping_ratios"], tool["physics"]["damping_ratios"])
    assert physics["mass"] == tool["physics"]["mass"]
    np.testing.assert_array_equal(physics["inertia"], tool["physics"]["inertia"])
    assert mine.link is not None and mine.link["outside_count"] == tool["link"]["outside"]
    assert mine.predicted_frequency_error == tool["predicted_frequency_error"]
    assert physics["spectrum_weights"] == tool["physics"]["spectrum_weights"]


@pytest.mark.parametrize("name", ["soap", "doorstop"])
def test_a_query_is_the_tools_bit_for_bit(cli, samples, database, name):
    path = samples / f"{name}.obj"
    vertices, faces = load(path)
    db = shapedb.Database(str(database))
    check_same_answer(db.query(vertices, faces, k=3), cli("query", database, path, "-k", 3)["queries"][0])
    corrected = db.query(vertices, faces, k=3, correct=True)
    check_same_answer(corrected, cli("query", database, path, "-k", 3, "--correct")["queries"][0])
    assert corrected.correction["morphs"] == 3 and corrected.correction["worst_quality"] > 0
    assert corrected.physics["spectrum_weights"] == []  # the correction's own modes
    nearest = db.query(vertices, faces, k=3, neighbours=1)
    check_same_answer(nearest, cli("query", database, path, "-k", 3, "--neighbours", 1)["queries"][0])
    assert nearest.physics["spectrum_weights"] == [1.0]
    with pytest.raises(ValueError, match="neighbours"):
        db.query(vertices, faces, neighbours=0)
    for candidates in (0, 101):
        with pytest.raises(ValueError, match="correction_candidates must be 1 to 100"):
            db.query(vertices, faces, correct=True, correction_candidates=candidates)


def test_query_results_hold_the_answers_data(samples, database):
    vertices, faces = load(samples / "pebble.obj")
    db = shapedb.Database(str(database))
    result = db.query(vertices, faces, k=4, material="aluminium")
    assert len(result.matches) == 4 and result.match is not None
    assert [m.distance for m in result.matches] == sorted(m.distance for m in result.matches)
    assert all(m.fidelity is not None and m.predicted_frequency_error > 0 for m in result.matches)
    physics = result.physics
    assert physics["material"]["name"] == "aluminium"
    nodes = physics["tet_nodes"]
    modes = physics["mode_shapes"]
    assert modes.shape == (8, len(nodes), 3)
    assert physics["tets"].shape[1] == 4 and physics["tets"].max() < len(nodes)
    assert (np.diff(physics["frequencies"]) >= 0).all() and physics["frequencies"][0] > 0
    # The mode shapes are M-orthonormal; the first, as a flat vector, is column 0 of the C++ matrix.
    assert np.isfinite(modes).all() and np.abs(modes).max() > 0
    assert physics["collision"] and {s["type"] for s in physics["collision"]} <= {"sphere", "box", "capsule"}
    link = result.link
    assert link["tets"].shape == (len(vertices),) and link["weights"].shape == (len(vertices), 4)
    np.testing.assert_allclose(link["weights"].sum(axis=1), 1.0, atol=1e-9)
    assert ((link["distances"] > 0).sum()) == link["outside_count"]
    # The linked position of every inside vertex is itself, interpolated from its tet's corners.
    inside = link["distances"] == 0
    corners = nodes[physics["tets"][link["tets"][inside]]]
    placed = np.einsum("vk,vkc->vc", link["weights"][inside], corners)
    np.testing.assert_allclose(placed, vertices[inside], atol=1e-9 * np.ptp(vertices))
    assert result.times_us["total"] > 0
    custom = db.query(vertices, faces, material={"density": 2700.0, "youngs_modulus": 70e9, "poisson_ratio": 0.33})
    assert custom.physics["mass"] == pytest.approx(2700.0 * result.mass_properties["volume"], rel=1e-12)


def test_query_many_answers_each_mesh_as_query_does_in_input_order(samples, database):
    db = shapedb.Database(str(database))
    meshes = [load(samples / f"{n}.obj") for n in ("soap", "egg", "hex-rod", "doorstop", "pebble")]
    vertices, faces = meshes[1]
    meshes.insert(2, (vertices, faces[:-1]))  # open: its own error, the others go on
    results = db.query_many(meshes, k=2)
    assert len(results) == len(meshes)
    assert isinstance(results[2], shapedb.Error) and results[2].code == "not_closed"
    for (v, f), many in zip(meshes, results):
        if isinstance(many, shapedb.Error):
            continue
        one = db.query(v, f, k=2)
        assert [m.name for m in many.matches] == [m.name for m in one.matches]
        np.testing.assert_array_equal(many.physics["frequencies"], one.physics["frequencies"])
        np.testing.assert_array_equal(many.physics["mode_shapes"], one.physics["mode_shapes"])


def test_threads_query_at_once_without_the_gil(samples, database):
    db = shapedb.Database(str(database))
    vertices, faces = load(samples / "doorstop.obj")
    expected = db.query(vertices, faces).physics["frequencies"]
    answers = []

    def work():
        for _ in range(3):
            answers.append(db.query(vertices, faces).physics["frequencies"])

    threads = [threading.Thread(target=work) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(answers) == 12
    for a in answers:
        np.testing.assert_array_equal(a, expected)


def test_arrays_outlive_the_result_and_the_database(samples, database):
    vertices, faces = load(samples / "soap.obj")
    db = shapedb.Database(str(database))
    result = db.query(vertices, faces)
    physics, link = result.physics, result.link
    views = {"modes": physics["mode_shapes"], "nodes": physics["tet_nodes"], "weights": link["weights"],
             "tets": link["tets"]}
    copies = {k: v.copy() for k, v in views.items()}
    # Views, not copies, and read-only: they share the result's memory.
    assert all(v.base is not None and not v.flags.writeable for v in views.values())
    with pytest.raises(ValueError):
        views["modes"][0, 0, 0] = 1.0
    del result, physics, link
    db.close()
    del db
    gc.collect()
    for key, view in views.items():
        np.testing.assert_array_equal(view, copies[key], err_msg=key)
    # A loaded mesh's vertices are the caller's own.
    assert vertices.flags.writeable


def test_info_and_a_resumed_build(tmp_path):
    path = tmp_path / "two.db"
    first = shapedb.build(str(path), entries=4, families="box,cone", modes=4)
    assert first == {"built": 4, "failed": 0, "skipped": 0, "seconds": first["seconds"]}
    again = shapedb.build(str(path), entries=4, families="box,cone", modes=4, resume=True)
    assert again["built"] == 0 and again["skipped"] == 4
    with shapedb.Database(str(path)) as db:
        info = db.info()
        assert len(db) == info["entries"] == 4
        assert info["families"] == {"box": 2, "cone": 2}
        assert info["parameters"]["modes"]["count"] == 4 and info["parameters"]["families"] == ["box", "cone"]
    with pytest.raises(ValueError, match="closed"):
        len(db)
    with pytest.raises(shapedb.Error, match="exists") as e:
        shapedb.build(str(path), entries=4, families="box,cone")
    assert e.value.code == "io"


def test_a_database_opened_with_one_index_answers_by_it_alone(samples, database):
    vertices, faces = load(samples / "doorstop.obj")
    whole = shapedb.Database(str(database)).query(vertices, faces, k=3)
    one = shapedb.Database(str(database), descriptors=["centroid-voxel"])
    answer = one.query(vertices, faces, k=3)
    assert [m.name for m in answer.matches] == [m.name for m in whole.matches]
    np.testing.assert_array_equal(answer.physics["frequencies"], whole.physics["frequencies"])
    with pytest.raises(shapedb.Error):
        one.query(vertices, faces, descriptor="moment")
    with pytest.raises(ValueError, match="descriptor"):
        shapedb.Database(str(database), descriptors=["fourier"])


def test_load_mesh_warns_of_what_it_did_to_the_file(tmp_path, samples):
    vertices, faces = load(samples / "egg.obj")
    inward = tmp_path / "inward.obj"
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in vertices.tolist()]
    lines += [f"f {a + 1} {c + 1} {b + 1}" for a, b, c in faces.tolist()]  # every face wound backwards
    inward.write_text("\n".join(lines) + "\n")
    with pytest.warns(UserWarning, match=r"inward.obj: the surface is wound inward .* flipped"):
        flipped_vertices, flipped_faces = load(inward)
    np.testing.assert_array_equal(flipped_vertices, vertices)
    assert shapedb.mass_properties(flipped_vertices, flipped_faces)["volume"] == pytest.approx(
        shapedb.mass_properties(vertices, faces)["volume"], rel=1e-12)


def test_save_mesh_writes_what_load_mesh_reads(tmp_path, samples):
    vertices, faces = load(samples / "doorstop.obj")
    far = vertices + [6.4e5, -1.3e6, 0.1]  # as a scan's coordinates may be
    for name in ("far.obj", "far.ply"):
        shapedb.save_mesh(str(tmp_path / name), far, faces)
        again_vertices, again_faces = load(tmp_path / name)
        np.testing.assert_array_equal(again_vertices, far)  # double precision, to the bit
        np.testing.assert_array_equal(again_faces, faces)
    for name in ("far.glb", "far.gltf"):
        shapedb.save_mesh(str(tmp_path / name), far, faces)
        again_vertices, again_faces = load(tmp_path / name)
        np.testing.assert_array_equal(again_faces, faces)
        assert np.abs(again_vertices - far).max() < 1e-7  # single precision about the centre, not the origin
    with pytest.raises(shapedb.Error, match=r"far.fbx: cannot write format '.fbx'"):
        shapedb.save_mesh(str(tmp_path / "far.fbx"), far, faces)


def test_load_mesh_drops_a_speck_unless_asked_to_keep_it(tmp_path, samples):
    vertices, faces = load(samples / "egg.obj")
    speck = vertices * 0.001 + vertices.max(axis=0) * 3.0  # a tiny egg beside the egg
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in np.vstack([vertices, speck]).tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in np.vstack([faces, faces + len(vertices)]).tolist()]
    path = tmp_path / "specked.obj"
    path.write_text("\n".join(lines) + "\n")
    with pytest.warns(UserWarning, match=r"specked.obj: 1 detached part under 0.001 of the largest part's area"):
        dropped_vertices, dropped_faces = load(path)
    np.testing.assert_array_equal(dropped_vertices, vertices)
    np.testing.assert_array_equal(dropped_faces, faces)
    kept_vertices, kept_faces = shapedb.load_mesh(str(path), keep_specks=True)
    assert len(kept_faces) == 2 * len(faces)


def test_load_mesh_reads_a_glb_as_the_obj_it_was_made_from(tmp_path, samples):
    """A binary glTF made here (float positions, unsigned int indices, one node moving the mesh) reads
    back as the OBJ's surface, moved, in single precision."""
    import json
    import struct

    vertices, faces = load(samples / "egg.obj")
    positions = vertices.astype("<f4").tobytes()
    indices = faces.astype("<u4").tobytes()
    gltf = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(positions) + len(indices)}],
        "bufferViews": [{"buffer": 0, "byteLength": len(positions)},
                        {"buffer": 0, "byteOffset": len(positions), "byteLength": len(indices)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(vertices), "type": "VEC3",
                       "min": vertices.min(axis=0).astype("f4").tolist(),
                       "max": vertices.max(axis=0).astype("f4").tolist()},
                      {"bufferView": 1, "componentType": 5125, "count": faces.size, "type": "SCALAR"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0, "translation": [1.0, 2.0, 3.0]}],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    }
    text = json.dumps(gltf).encode()
    text += b" " * (-len(text) % 4)
    binary = positions + indices
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(binary), 0x004E4942) + binary
    path = tmp_path / "egg.glb"
    path.write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks)

    glb_vertices, glb_faces = load(path)
    np.testing.assert_array_equal(glb_faces, faces)
    np.testing.assert_array_equal(glb_vertices, vertices.astype(np.float32).astype(np.float64) + [1.0, 2.0, 3.0])


def test_load_mesh_reads_a_collada_file_through_assimp(tmp_path, samples, cli):
    """A COLLADA file written here, read by assimp in its worker process: the OBJ's surface in single
    precision, placed by its node, welded as the tool reads it."""
    vertices, faces = load(samples / "egg.obj")
    xyz = " ".join(f"{c:.9g}" for c in vertices.ravel())
    corners = " ".join(str(i) for i in faces.ravel())
    path = tmp_path / "egg.dae"
    path.write_text(
        '<?xml version="1.0" encoding="utf-8"?>\n'
        '<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">'
        '<asset><unit meter="1"/><up_axis>Y_UP</up_axis></asset><library_geometries><geometry id="g"><mesh>'
        f'<source id="p"><float_array id="a" count="{vertices.size}">{xyz}</float_array>'
        f'<technique_common><accessor source="#a" count="{len(vertices)}" stride="3">'
        '<param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>'
        '</accessor></technique_common></source><vertices id="v"><input semantic="POSITION" source="#p"/></vertices>'
        f'<triangles count="{len(faces)}"><input semantic="VERTEX" source="#v" offset="0"/><p>{corners}</p></triangles>'
        '</mesh></geometry></library_geometries><library_visual_scenes><visual_scene id="s"><node id="n">'
        '<translate>1 2 3</translate><instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>'
        '<scene><instance_visual_scene url="#s"/></scene></COLLADA>\n')
    dae_vertices, dae_faces = load(path)
    assert len(dae_faces) == len(faces)
    tool = cli("inspect", path)
    assert shapedb.mass_properties(dae_vertices, dae_faces)["volume"] == tool["volume"]
    np.testing.assert_allclose(shapedb.mass_properties(dae_vertices, dae_faces)["volume"],
                               shapedb.mass_properties(vertices, faces)["volume"], rtol=1e-5)


# ---- fracture --------------------------------------------------------------------------------------------


def test_fracture_gives_the_tools_fragments(tmp_path, samples, cli_path):
    path = samples / "pebble.obj"
    vertices, faces = load(path)
    broken = shapedb.fracture(vertices, faces, pieces=6, seed=3)
    subprocess.run([cli_path, "fracture", str(path), "--pieces", "6", "--seed", "3", "--out", str(tmp_path)],
                   check=True, capture_output=True)
    written = sorted(tmp_path.glob("fragment-*.obj"))
    assert len(written) == len(broken["fragments"]) >= 6
    total = 0.0
    for (v, f), file in zip(broken["fragments"], written):
        fv, ff = load(file)
        np.testing.assert_array_equal(v, fv)
        np.testing.assert_array_equal(f, ff)
        total += shapedb.mass_properties(v, f)["volume"]
    assert total == pytest.approx(broken["kept_volume"], rel=1e-9)
    assert broken["kept_fraction"] == pytest.approx(broken["kept_volume"] / broken["solid_volume"])
    assert 0.97 < broken["kept_fraction"] <= 1.0
    same = shapedb.fracture(vertices, faces, pieces=6, seed=3)
    for (a, _), (b, _) in zip(broken["fragments"], same["fragments"]):
        np.testing.assert_array_equal(a, b)


# ---- bad input -------------------------------------------------------------------------------------------


def test_bad_input_raises_shapedbs_message(tmp_path, samples, database):
    vertices, faces = load(samples / "egg.obj")
    with pytest.raises(ValueError, match=r"vertices must have shape \(n, 3\)"):
        shapedb.mass_properties(vertices[:, :2], faces)
    with pytest.raises(ValueError, match=r"faces must have shape \(m, 3\)"):
        shapedb.mass_properties(vertices, faces.ravel())
    with pytest.raises(TypeError, match="faces must be an integer"):
        shapedb.mass_properties(vertices, faces.astype(np.float64))
    with pytest.raises(TypeError, match="vertices must be a real"):
        shapedb.mass_properties(vertices.astype(np.complex128), faces)
    with pytest.raises(ValueError, match="is not a vertex index"):
        shapedb.mass_properties(vertices, -faces)
    with pytest.raises(shapedb.Error, match="refers to vertex") as e:
        shapedb.mass_properties(vertices, faces + len(vertices))
    assert e.value.code == "index_out_of_range"
    with pytest.raises(shapedb.Error, match="not closed") as e:
        shapedb.mass_properties(vertices, faces[:-1])
    assert e.value.code == "not_closed"
    approximate = shapedb.mass_properties(vertices, faces[:-1], approximate=True)
    assert approximate["is_approximate"]
    nan = vertices.copy()
    nan[0, 0] = np.nan
    with pytest.raises(shapedb.Error) as e:
        shapedb.describe(nan, faces)
    assert e.value.code == "non_finite"

    missing = tmp_path / "nowhere.obj"
    with pytest.raises(shapedb.Error, match="nowhere.obj") as e:
        shapedb.load_mesh(str(missing))
    assert e.value.code == "io"
    garbage = tmp_path / "garbage.ply"
    garbage.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 99999999\n")
    with pytest.raises(shapedb.Error, match="garbage.ply"):
        shapedb.load_mesh(str(garbage))

    foreign = tmp_path / "foreign.db"
    foreign.write_text("not a database, just text\n" * 100)
    with pytest.raises(shapedb.Error, match="foreign.db"):
        shapedb.Database(str(foreign))
    with pytest.raises(shapedb.Error, match="nothere.db"):
        shapedb.Database(str(tmp_path / "nothere.db"))

    db = shapedb.Database(str(database))
    with pytest.raises(shapedb.Error, match="not closed"):
        db.query(vertices, faces[:-1])
    with pytest.raises(shapedb.Error, match="steel"):  # the presets are named
        db.query(vertices, faces, material="unobtainium")
    with pytest.raises(shapedb.Error):
        db.query(vertices, faces, material={"density": -1.0, "youngs_modulus": 1e9})
    with pytest.raises(ValueError, match="descriptor"):
        db.query(vertices, faces, descriptor="fourier")
    with pytest.raises(ValueError, match="k must be"):
        db.query(vertices, faces, k=0)
    with pytest.raises(ValueError, match="pairs"):
        db.query_many([(vertices, faces, None)])
    with pytest.raises(shapedb.Error):
        shapedb.fracture(vertices, faces, pieces=0)
    with pytest.raises(shapedb.Error, match="unknown family 'teapot'"):
        shapedb.build(str(tmp_path / "x.db"), entries=4, families="box,teapot")


# ---- the example -----------------------------------------------------------------------------------------


def test_the_fracture_example_runs(tmp_path, samples, database):
    pytest.importorskip("matplotlib")
    script = SOURCE_DIR / "examples" / "python" / "fracture_frequencies.py"
    plot = tmp_path / "frequencies.png"
    done = subprocess.run([sys.executable, str(script), str(database), str(samples / "pebble.obj"), "--pieces", "12",
                           "--plot", str(plot)], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert plot.stat().st_size > 1000 and plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = [line.split() for line in done.stdout.splitlines() if line.startswith("fragment-")]
    assert len(rows) >= 12
    assert all(float(r[2]) > 0 for r in rows)  # a first frequency for every fragment
