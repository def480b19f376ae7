"""Every option declared once: the module's functions, their stubs, their help and the Dask
front end all come from the library's table (voxelkit.OPTIONS), with the CLI's defaults and
errors."""

import ast
import inspect
import pathlib

import numpy as np
import pytest

import voxelkit
from voxelkit import distributed

from conftest import REPO

#: The package's stubs as the repository holds them (written by `python -m voxelkit._stubs`).
PACKAGE_STUBS = REPO / "python" / "voxelkit" / "__init__.pyi"
#: The extension's own stubs (the Grid class), written by hand.
STUBS = pathlib.Path(voxelkit.__file__).with_name("_voxelkit.pyi")
#: Each function's positional inputs and the table entry of its options.
FUNCTIONS = {
    "mesh": (["source"], "mesh"),
    "solid": (["source"], "solid"),
    "subdiv": (["source"], "subdiv"),
    "implicit": (["formula"], "implicit"),
    "lines": (["source"], "lines"),
    "measure": (["source"], "measure"),
    "combine": (["a", "b"], "combine"),
    "signed_distance": (["mesh", "points"], "query"),
    "contains": (["mesh", "points"], "query"),
    "csg": (["tree"], None),
}
SPHERE = "x^2 + y^2 + z^2 - 0.5"


def expected(request):
    """(name, default) of a function's options: its request's, the limits, progress."""
    fields = (voxelkit.OPTIONS[request]["fields"] if request else []) + voxelkit.OPTIONS["limits"]["fields"]
    return [(f["name"], f["default"]) for f in fields] + [("progress", None)]


def plain(value):
    return list(value) if isinstance(value, tuple) else value


def test_the_stubs_are_written_from_the_table():
    from voxelkit import _stubs

    assert PACKAGE_STUBS.read_text() == _stubs.stubs(), "run `python -m voxelkit._stubs python/voxelkit/__init__.pyi`"


def test_stubs_declare_the_tables_options_defaults_and_help():
    tree = ast.parse(PACKAGE_STUBS.read_text())
    stubs = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    for name, (inputs, request) in FUNCTIONS.items():
        args = stubs[name].args
        names = [a.arg for a in args.args]
        assert names[: len(inputs)] == inputs, name
        defaults = [plain(ast.literal_eval(d)) for d in args.defaults]
        assert list(zip(names[len(inputs):], defaults)) == expected(request), name
        assert all(a.annotation is not None for a in args.args), name
        assert ast.get_docstring(stubs[name]) == inspect.cleandoc(getattr(voxelkit, name).__doc__), name
    # Everything the package exports is declared.
    declared = set(stubs) | {a.asname for n in tree.body if isinstance(n, ast.ImportFrom) for a in n.names}
    declared |= {n.target.id for n in tree.body if isinstance(n, ast.AnnAssign)}
    assert set(voxelkit.__all__) <= declared


def test_signatures_and_help_document_every_option():
    for name, (inputs, request) in FUNCTIONS.items():
        fn = getattr(voxelkit, name)
        params = list(inspect.signature(fn).parameters.values())
        assert [p.name for p in params[: len(inputs)]] == inputs
        got = [(p.name, plain(p.default)) for p in params[len(inputs):]]
        assert got == expected(request), name
        for option, _ in expected(request):
            assert f"\n{option} = " in fn.__doc__ or f"\n{option}:" in fn.__doc__, (name, option)


def test_a_bad_value_gets_the_clis_error(data):
    path = data / "meshes" / "bunny-closed.obj"
    with pytest.raises(ValueError, match="separability must be 6 or 26, not `7`"):
        voxelkit.mesh(path, separability=7)
    with pytest.raises(ValueError, match="the fill method must be flood, depth-layers or beam, not `x`"):
        voxelkit.solid(path, method="x")
    with pytest.raises(ValueError, match="band must be a positive number"):
        voxelkit.mesh(path, sdf=True, band=-1.0)
    with pytest.raises(ValueError, match="band: must be a finite number"):
        voxelkit.mesh(path, sdf=True, band=float("nan"))
    with pytest.raises(TypeError, match="unexpected keyword argument 'separabilty'"):
        voxelkit.mesh(path, separabilty=6)


def test_zero_threads_and_zero_memory_mean_the_defaults():
    default = voxelkit.implicit(SPHERE, resolution=24)
    zero = voxelkit.implicit(SPHERE, resolution=24, threads=0, max_memory_mib=0)
    assert len(zero) > 0 and zero.same_voxels(default)


def test_numpy_numbers_are_options():
    grid = voxelkit.implicit(SPHERE, resolution=np.int64(24), bounds=np.array([-1.0, 1.0]))
    assert grid.same_voxels(voxelkit.implicit(SPHERE, resolution=24))


def test_every_dask_option_is_the_tables_in_run_and_on_the_command_line(capsys):
    helps = {}
    for command in ("mesh", "solid"):
        with pytest.raises(SystemExit):
            distributed.main([command, "--help"])
        helps[command] = " ".join(capsys.readouterr().out.split())
    # Each command shows the options that act on it: separability the surface's, inside the solid's.
    only = {"separability": "mesh", "inside": "solid"}
    params = inspect.signature(distributed.run).parameters
    flags = {"max_memory_mib": "--max-memory"}
    fields = voxelkit.OPTIONS["distributed"]["fields"]
    for f in fields:
        name, default = f["name"], f["default"]
        assert params[name].default == default, name
        assert f"\n{name} = " in distributed.run.__doc__, name
        flag = flags.get(name, "--" + name.replace("_", "-"))
        for command, text in helps.items():
            if only.get(name, command) != command:
                assert flag not in text, (command, name)
                continue
            assert flag in text, (command, name)
            if default is not None:
                assert f"(default {default})" in text, (command, name)
            for choice in f["choices"]:
                assert str(choice) in text, (command, name, choice)
    assert len(fields) >= 7


def test_a_bad_dask_option_gets_the_tables_error_before_any_work(data, tmp_path):
    path = data / "meshes" / "bunny-closed.obj"
    with pytest.raises(ValueError, match="separability must be 6 or 26, not `7`"):
        distributed.mesh(path, tmp_path / "b.vdb", separability=7)
    with pytest.raises(TypeError, match="unexpected keyword argument 'separabilty'"):
        distributed.mesh(path, tmp_path / "b.vdb", separabilty=6)
    with pytest.raises(TypeError, match="threads"):
        distributed.mesh(path, tmp_path / "b.vdb", threads=2)
    assert not list(tmp_path.iterdir())


def test_pyopenvdb_reads_the_fit_and_separability_as_numbers(tmp_path, pyopenvdb):
    voxelkit.implicit(SPHERE, resolution=24).write(tmp_path / "r.vdb")
    grid = voxelkit.mesh((
        [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
        [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    ), voxel_size=0.125, separability=6)
    grid.write(tmp_path / "h.vdb")
    implicit = pyopenvdb.readAllGridMetadata(str(tmp_path / "r.vdb"))[0]
    assert implicit["resolution"] == 24 and isinstance(implicit["resolution"], int)
    mesh = pyopenvdb.readAllGridMetadata(str(tmp_path / "h.vdb"))[0]
    assert mesh["voxel_size"] == 0.125 and isinstance(mesh["voxel_size"], float)
    assert mesh["separability"] == 6 and isinstance(mesh["separability"], int)


def test_bad_dask_numbers_are_value_errors_naming_the_option(data, tmp_path):
    path = data / "meshes" / "bunny-closed.obj"
    with pytest.raises(ValueError, match="brick"):
        distributed.mesh(path, tmp_path / "b.vdb", brick=-8)
    with pytest.raises(ValueError, match="brick size must be a positive multiple of 8"):
        distributed.mesh(path, tmp_path / "b.vdb", brick=12)
    assert not list(tmp_path.iterdir())


def test_the_write_stub_declares_the_tables_write_options():
    tree = ast.parse(STUBS.read_text())
    grid = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Grid")
    table = [(f["name"], f["default"]) for f in voxelkit.OPTIONS["write"]["fields"]]
    for method in ("write", "write_vdb"):
        args = next(n for n in grid.body if isinstance(n, ast.FunctionDef) and n.name == method).args
        names = [a.arg for a in args.args][2:]
        defaults = [plain(ast.literal_eval(d)) for d in args.defaults]
        # `grids=None` in the stub means the table's empty list: every grid but `voxels`.
        defaults = [[] if d is None and n == "grids" else d for n, d in zip(names, defaults)]
        assert list(zip(names, defaults)) == table, method


def test_write_takes_the_tables_options_and_refuses_a_bad_one(tmp_path):
    grid = voxelkit.implicit(SPHERE, resolution=16)
    grid.write(tmp_path / "z.vdb", compression="zip", grids=["density"])
    with pytest.raises(ValueError, match="the compression must be blosc, zip or none, not `lz4`"):
        grid.write(tmp_path / "x.vdb", compression="lz4")
    with pytest.raises(TypeError, match="unexpected keyword argument 'compress'"):
        grid.write(tmp_path / "x.vdb", compress="zip")
