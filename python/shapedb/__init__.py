"""shapedb: physical data for objects that have only a surface mesh.

A surface is two NumPy arrays: vertices ``(n, 3)`` float64 in metres and faces ``(m, 3)`` integer,
counter-clockwise seen from outside. Arrays handed back are views into shapedb's own data where its layout
allows (vertices, mode shapes, a link's weights), read-only when they belong to a shared result, and stay
valid after the object that handed them out is gone. Every failure of shapedb itself raises
:class:`shapedb.Error`, with shapedb's message (naming the file or the problem) and ``.code``
(``"not_closed"``, ``"io"``, ...); arrays of the wrong shape or dtype raise ``ValueError`` or ``TypeError``.
Long work (building, querying, fracturing) releases the GIL.

Functions
---------
load_mesh(path, *, scale=1.0, keep_specks=False) -> (V, F)
    OBJ, PLY, OFF, STL, glTF (.gltf, .glb), FBX or COLLADA (.dae); a surface wound inward is flipped, an open one welded where
    that closes it, detached specks (under 0.001 of the largest part's area) dropped, and a UserWarning
    naming the file says so.
save_mesh(path, V, F, *, binary=True)
    Writes OBJ or PLY (double precision; ``binary`` for PLY), or glTF (``.glb``, ``.gltf``: single precision
    about the mesh's centre, for a game engine), by extension.
mass_properties(V, F, *, density=1.0, approximate=False) -> dict
    Exact volume, mass, area, centre of mass and inertia (about the centre of mass) of the enclosed solid.
    ``approximate=True`` accepts an open surface (vertex point masses; ``is_approximate`` says so).
normalize(V, F) -> dict
    The canonical frame: ``canonical_from_mesh`` (4×4), its inverse, scale, principal axes and moments.
describe(V, F, *, kind="centroid-voxel", grid=10, sampling="area") -> dict
    The shape descriptor a database searches by: filled ``cells``, their surface ``centroids`` and
    ``weights``, and the canonical ``moments``.
build(path, *, entries=1400, families="all", elements="quadratic", modes=20, threads=0, resume=False)
    Builds a database file (minutes for the default catalog). ``families`` as the CLI takes it:
    ``"box,fragment:3"``. Returns counts and seconds.
fracture(V, F, *, pieces=20, seed=1, resolution=0, max_triangles=3000) -> dict
    Breaks a closed surface into fragments: ``fragments`` is a list of (V, F); the kept volume beside.
materials(), families()
    The material presets' and the catalog families' names.

Database(path, *, cache_entries=256, descriptors=None)
    ``query(V, F, *, k=1, descriptor="centroid-voxel", material="steel", correct=False, fidelity=True,
    approximate=False, adapt=True, correction_candidates=3, neighbours=3) -> QueryResult``;
    ``query_many(meshes, ...)``
    answers a list of (V, F) at once over all cores, in input order, a failed mesh's :class:`Error` in its
    slot; ``info()``; ``len(db)``; ``close()``; usable in ``with``. ``material`` is a preset's name or a
    dict with ``density``, ``youngs_modulus`` and ``poisson_ratio``. ``descriptors`` (say
    ``["centroid-voxel"]``) builds only those kinds' indexes at open, a third of the reading each: a query
    by another kind is then an error.

QueryResult
    ``matches`` (best first: ``name``, ``family``, ``distance``, ``fidelity``,
    ``predicted_frequency_error``), ``match`` (the answered one), ``physics`` (``mass``, ``inertia``,
    ``frequencies`` in Hz, ``damping_ratios``, ``mode_shapes`` ``(modes, nodes, 3)``, ``tet_nodes``,
    ``tets``, ``collision``, ``warnings``, ``spectrum_weights``: the weight of each of the first matches
    whose spectra the eigenvalues were blended from, ``neighbours`` of them; ``[1.0]`` for one entry's own,
    ``[]`` corrected), ``link`` (per query vertex: ``tets``, ``weights`` ``(n, 4)``,
    ``distances``), ``correction`` (with ``correct=True``), ``predicted_frequency_error``, ``times_us``.
"""

from ._shapedb import (  # noqa: F401
    Database,
    Error,
    Match,
    QueryResult,
    build,
    describe,
    families,
    fracture,
    load_mesh,
    mass_properties,
    materials,
    normalize,
    save_mesh,
)

__all__ = [
    "Database",
    "Error",
    "Match",
    "QueryResult",
    "build",
    "describe",
    "families",
    "fracture",
    "load_mesh",
    "mass_properties",
    "materials",
    "normalize",
    "save_mesh",
]
