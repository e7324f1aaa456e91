"""The package as a user meets it: stubs that match the module, docstrings, the example script."""

import inspect
import os
import pathlib
import re
import subprocess
import sys

import pytest

import ellreloc
from ellreloc import _ellreloc

PACKAGE = pathlib.Path(ellreloc.__file__).parent


def public_items(module):
    return [(n, v) for n, v in vars(module).items() if not n.startswith("_") and not inspect.ismodule(v)]


def public(module):
    return {n for n, _ in public_items(module)}


def stub_names(path):
    text = path.read_text()
    return set(re.findall(r"^(?:class|def) (\w+)", text, re.M)) | set(re.findall(r"^(\w+): ", text, re.M))


@pytest.mark.parametrize("module, stub", [(_ellreloc, "_ellreloc.pyi"), (ellreloc.sim, "sim.pyi")])
def test_stubs_name_every_public_name_and_nothing_else(module, stub):
    assert stub_names(PACKAGE / stub) == public(module)


def test_stub_members_exist():
    """Each `def` or attribute in a stubbed class exists on the class."""
    for stub, module in (("_ellreloc.pyi", _ellreloc), ("sim.pyi", ellreloc.sim)):
        cls = None
        for line in (PACKAGE / stub).read_text().splitlines():
            if m := re.match(r"class (\w+)", line):
                cls = getattr(module, m.group(1))
            elif cls is not None and (m := re.match(r"    (?:def )?(\w+)\b", line)):
                if m.group(1) not in ("pass",) and not line.strip().startswith(("#", "@", '"""')):
                    assert hasattr(cls, m.group(1)), f"{stub}: {cls.__name__}.{m.group(1)}"
            elif line and not line.startswith(" "):
                cls = None


def test_stub_classes_list_every_member():
    """Each public member of a stubbed class is in its stub (scripts/python_stubs.py rewrites
    them): a field or method added to the bindings without new stubs fails here."""
    for stub, module in (("_ellreloc.pyi", _ellreloc), ("sim.pyi", ellreloc.sim)):
        listed, cls = {}, None
        for line in (PACKAGE / stub).read_text().splitlines():
            if m := re.match(r"class (\w+)", line):
                cls = m.group(1)
                listed[cls] = set()
            elif cls is not None and (m := re.match(r"    (?:def )?(\w+)\b", line)):
                listed[cls].add(m.group(1))
            elif line and not line.startswith(" "):
                cls = None
        for name, members in listed.items():
            missing = {m for m in vars(getattr(module, name)) if not m.startswith("_")} - members
            assert not missing, f"{stub}: {name} lacks {sorted(missing)}"


def test_the_package_lists_the_library_and_no_module_it_imports():
    modules = {n for n in dir(ellreloc) if not n.startswith("_") and inspect.ismodule(getattr(ellreloc, n))}
    assert modules == {"sim"}
    assert public(ellreloc) == public(_ellreloc)


def test_without_numpy_the_import_says_what_is_missing():
    env = dict(os.environ, PYTHONPATH=str(PACKAGE.parent))
    run = subprocess.run([sys.executable, "-c", "import sys; sys.modules['numpy'] = None; import ellreloc"],
                         capture_output=True, text=True, env=env)
    assert run.returncode != 0
    assert f"ellreloc needs numpy, which {sys.executable} cannot import" in run.stderr.splitlines()[-1]


def test_every_class_function_and_method_is_exercised_by_a_test():
    """Each public class, function and method is named in some test (fields are covered by the
    option round trips of test_surface.py)."""
    words = set(re.findall(r"\w+", "\n".join(p.read_text() for p in pathlib.Path(__file__).parent.glob("test_*.py"))))
    missing = []
    for module in (_ellreloc, ellreloc.sim):
        for name, value in public_items(module):
            if name not in words:
                missing.append(name)
            if inspect.isclass(value):
                missing += [f"{name}.{m}" for m, v in vars(value).items()
                            if not m.startswith("_") and m not in words and (callable(v) or isinstance(v, staticmethod))
                            and not (hasattr(value, "__members__") and m in value.__members__)]
    assert not missing, missing


def test_every_function_and_class_has_a_docstring_or_is_plain_data():
    missing = [n for n in public(_ellreloc) if inspect.isroutine(getattr(_ellreloc, n))
               and not (getattr(_ellreloc, n).__doc__ or "").split("\n", 1)[-1].strip()]
    assert not missing, missing


def test_the_example_relocalizes_fr2(data_dir):
    example = pathlib.Path(os.environ.get("ELLRELOC_EXAMPLES", pathlib.Path(__file__).parents[2] / "examples" / "python"))
    env = dict(os.environ, PYTHONPATH=str(PACKAGE.parent))
    out = subprocess.run([sys.executable, str(example / "relocalize.py"), str(data_dir / "tum_fr2_desk")],
                         check=True, capture_output=True, text=True, env=env).stdout
    assert "camera centre" in out and "observation" in out


def test_the_track_example_beats_each_frame_alone(data_dir):
    example = pathlib.Path(os.environ.get("ELLRELOC_EXAMPLES", pathlib.Path(__file__).parents[2] / "examples" / "python"))
    env = dict(os.environ, PYTHONPATH=str(PACKAGE.parent))
    out = subprocess.run([sys.executable, str(example / "track.py"), str(data_dir / "tum_fr2_desk"), "5"],
                         check=True, capture_output=True, text=True, env=env).stdout
    valid = {line.split(":")[0]: float(line.split(", ")[1].split("%")[0]) for line in out.splitlines()}
    assert valid["along the track"] > valid["alone"] + 5  # measured: 73.7% against 62.1%
    assert valid["along the track of a monocular odometry"] > valid["alone"] + 5  # measured: 71.7%


def test_the_monocular_example_maps_in_the_unit_its_objects_tell(data_dir):
    example = pathlib.Path(os.environ.get("ELLRELOC_EXAMPLES", pathlib.Path(__file__).parents[2] / "examples" / "python"))
    env = dict(os.environ, PYTHONPATH=str(PACKAGE.parent))
    out = subprocess.run([sys.executable, str(example / "monocular.py"), str(data_dir / "tum_fr2_desk")],
                         check=True, capture_output=True, text=True, env=env).stdout
    unit = float(out.split("the map records its unit: ")[1].split(" m")[0])
    assert abs(unit / 2.5 - 1.0) < 0.2, out  # measured 2.18 m: fr2's objects are smaller than typical ones
    valid = float(out.split("relocalized: 198 keyframes, ")[1].split("%")[0])
    assert valid > 65.0, out  # measured 72.2%, 3.4 cm told in metres
