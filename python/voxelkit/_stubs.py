"""Writes the package's type stubs, ``__init__.pyi``, from the table of options and the
functions made from it, so that the stubs, ``help()`` and the functions say the same thing:
``python -m voxelkit._stubs [PATH]`` (default: beside this file)."""

import pathlib
import sys

import voxelkit
from voxelkit import _FUNCTIONS, _default, _option_fields

HEADER = '''"""Type stubs of voxelkit, written by ``python -m voxelkit._stubs`` from the table of
options (voxelkit.OPTIONS): edit the table, not this file."""

from os import PathLike
from typing import Any, Callable, Dict, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._voxelkit import DEFAULT_RESOLUTION as DEFAULT_RESOLUTION
from ._voxelkit import Grid as Grid
from ._voxelkit import __version__ as __version__
from ._voxelkit import read_vdb as read_vdb

Path = Union[str, PathLike]
#: A path, a (vertices, faces) pair of arrays, or an object with them (trimesh, Open3D).
MeshSource = Union[Path, Tuple[npt.ArrayLike, npt.ArrayLike], Any]
Progress = Callable[[str, int, int], Any]

#: Every function's options (see the package docstring).
OPTIONS: Dict[str, Dict[str, Any]]
bl_info: Dict[str, Any]

def register() -> None:
    """Registers the Blender add-on (inside Blender only)."""

def unregister() -> None:
    """Unregisters the Blender add-on."""
'''


def _docstring(text):
    body = text.replace("\\", "\\\\").replace('"""', '\\"\\"\\"')
    lines = body.split("\n")
    indented = [lines[0]] + [("    " + line).rstrip() for line in lines[1:]]
    return '    """' + "\n".join(indented) + '"""'


def function_stub(name):
    """One function's stub: its inputs, its options with their types and defaults, and
    its help text as the docstring."""
    inputs, request, returns, _ = _FUNCTIONS[name]
    lines = [f"def {name}("]
    lines += [f"    {i}: {annotation}," for i, annotation in inputs.items()]
    for f in _option_fields(request):
        lines.append(f"    {f['name']}: {f['python_type']} = {_default(f['default'])!r},")
    lines.append("    progress: Optional[Progress] = None,")
    lines.append(f") -> {returns}:")
    lines.append(_docstring(getattr(voxelkit, name).__doc__))
    return "\n".join(lines) + "\n"


def stubs():
    """The text of ``__init__.pyi``."""
    return "\n".join([HEADER] + [function_stub(name) for name in _FUNCTIONS])


if __name__ == "__main__":
    target = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).with_name("__init__.pyi")
    target.write_text(stubs())
    print(f"wrote {target}")
