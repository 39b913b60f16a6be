"""What the wheel installs: one import name, ``asymslide`` (its subpackages model, atlas and app mapped from the
repository's top-level folders), every data file the app needs, and the asymslide console script; what each extra
adds; the lock; the layers' imports."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

from asymslide import cli

ROOT = Path(__file__).resolve().parents[2]

#: the subpackages of asymslide and the repository folders they are built from (pyproject.toml's package-dir)
SUBPACKAGES = {"model": "model", "atlas": "atlas", "app": "app"}


@pytest.fixture(scope="module")
def wheel_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The wheel built from a copy of the working tree (setuptools writes build/ into the tree it builds)."""
    out = tmp_path_factory.mktemp("wheel")
    src = out / "src"
    shutil.copytree(ROOT, src, ignore=shutil.ignore_patterns(".venv", ".git", "build", "*.egg-info", "__pycache__",
                                                              ".numba_cache", ".pytest_cache", ".hypothesis"))
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(out), str(src)],
                   check=True, capture_output=True, timeout=600)
    (path,) = out.glob("asymslide-*.whl")
    return path


@pytest.fixture(scope="module")
def wheel(wheel_path: Path) -> zipfile.ZipFile:
    return zipfile.ZipFile(wheel_path)


@pytest.mark.slow
def test_the_wheel_installs_one_import_name_and_the_data_files(wheel: zipfile.ZipFile) -> None:
    names = wheel.namelist()
    top = {n.split("/")[0] for n in names if not n.split("/")[0].endswith((".dist-info", ".data"))}
    assert top == {"asymslide"}
    for needed in ("asymslide/app/presets.json", "asymslide/app/static/asymslide.css",
                   "asymslide/app/static/logo.svg", "asymslide/app/static/favicon.svg",
                   "asymslide/model/materials.json", "asymslide/app/reference/physics.md", "asymslide/app/main.py",
                   "asymslide/cli.py", "asymslide/atlas/sweep.py", "asymslide/model/_kernels/newton.py"):
        assert needed in names, needed
    assert not [n for n in names if "/tests/" in n or "benchmarks/" in n]
    # every module of every layer, subpackages included (pyproject.toml lists the packages one by one)
    for sub, folder in SUBPACKAGES.items():
        modules = {f"asymslide/{sub}/{p.relative_to(ROOT / folder).as_posix()}"
                   for p in (ROOT / folder).rglob("*.py") if "__pycache__" not in p.parts}
        assert modules - set(names) == set(), sub
    entry = next(n for n in names if n.endswith("entry_points.txt"))
    assert "asymslide = asymslide.cli:main" in wheel.read(entry).decode()


# ---------------------------------------------------------------------------------------------------------------
# extras: `pip install asymslide` gives the model; [atlas] the engine; [app] the web app
# ---------------------------------------------------------------------------------------------------------------

#: what the core install provides: the model's dependencies
CORE = ("numpy", "scipy", "numba", "llvmlite")


def _core_only_python(tmp_path: Path, wheel_path: Path) -> tuple[Path, set[str]]:
    """A fresh virtual environment holding only what `pip install asymslide` installs: the model's dependencies
    (linked from this environment) and the wheel, installed by pip. Its python, and the entries the wheel added to
    its site-packages."""
    venv = tmp_path / "core-only"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=120)
    site = Path(sysconfig.get_path("purelib"))
    (target,) = venv.glob("lib/python*/site-packages")
    wanted = {name.lower() for name in CORE}
    for entry in site.iterdir():
        if entry.name.split("-")[0].split(".")[0].lower() in wanted and not entry.name.endswith(".pth"):
            (target / entry.name).symlink_to(entry)
    before = {e.name for e in target.iterdir()}
    python = venv / "bin" / "python"
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "--quiet", "--no-deps",
                    "--no-index", str(wheel_path)], check=True, capture_output=True, timeout=300)
    return python, {e.name for e in target.iterdir()} - before


#: a working directory of a user's notebooks, whose own modules have the generic names of the layers
USER_MODULES = {name: f'raise ImportError("the user\'s {name}.py was imported")\n'
                for name in ("model", "app", "atlas")}


@pytest.mark.slow
def test_the_core_install_gives_the_model_under_one_name_and_each_command_names_its_extra(
        tmp_path: Path, wheel_path: Path) -> None:
    python, added = _core_only_python(tmp_path, wheel_path)
    assert {a for a in added if a != "__pycache__"} == {"asymslide", "asymslide-0.1.0.dist-info"}
    work = tmp_path / "notebooks"
    work.mkdir()
    for name, text in USER_MODULES.items():
        (work / f"{name}.py").write_text(text)
    model = subprocess.run([str(python), "-c", "from asymslide import model; "
                            "print(float(model.rayleigh_speed(0.25)), model.__file__)"],
                           capture_output=True, text=True, timeout=300, cwd=work)
    assert model.returncode == 0, model.stderr
    from asymslide import model as here

    assert float(model.stdout.split()[0]) == float(here.rayleigh_speed(0.25))  # the same model, from the core alone
    assert "/site-packages/asymslide/model/" in model.stdout.split()[1]
    mine = subprocess.run([str(python), "-c", "import model"], capture_output=True, text=True, timeout=60, cwd=work)
    assert "the user's model.py was imported" in mine.stderr  # the user's name is the user's, as it should be
    hidden = subprocess.run([str(python), "-c", "import panel"], capture_output=True, text=True, timeout=60)
    assert "No module named 'panel'" in hidden.stderr  # the environment really lacks the app's dependencies
    for command, extra, missing in ((["serve"], "app", "panel"),
                                    (["sweep", "--axis", "gamma=1:2:2", "--out", str(tmp_path / "a.zarr")],
                                     "atlas", "xarray"),
                                    (["info", str(tmp_path / "a.zarr")], "atlas", "dask")):
        run = subprocess.run([str(python), "-m", "asymslide", *command], capture_output=True, text=True, timeout=120,
                             cwd=work)
        assert run.returncode == cli.EXIT_MISSING_EXTRA, run.stderr
        assert f"pip install 'asymslide[{extra}]'" in run.stderr and missing in run.stderr, run.stderr
        assert "Traceback" not in run.stderr
        assert not (tmp_path / "a.zarr").exists()
    version = subprocess.run([str(python), "-m", "asymslide", "--version"], capture_output=True, text=True,
                             timeout=60, cwd=work)
    assert version.returncode == 0 and version.stdout.startswith("asymslide "), version.stderr


def test_a_missing_extra_is_named_before_the_command_runs(monkeypatch: pytest.MonkeyPatch,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    real = cli.metadata.distribution

    def without_panel(name: str):
        if name.lower() == "panel":
            raise cli.metadata.PackageNotFoundError(name)
        return real(name)

    monkeypatch.setattr(cli.metadata, "distribution", without_panel)
    monkeypatch.setattr(cli, "_serve", lambda _args: pytest.fail("the server was started"))
    assert cli.missing_requirements("app") == ["panel"]
    assert cli.missing_requirements("atlas") == []
    assert cli.main(["serve"]) == cli.EXIT_MISSING_EXTRA
    err = capsys.readouterr().err
    assert "'asymslide serve' needs the web app's dependencies" in err and "(missing: panel)" in err
    assert "pip install 'asymslide[app]'" in err


def test_nested_extras_are_followed(monkeypatch: pytest.MonkeyPatch) -> None:
    """[app] requires asymslide[atlas], which requires dask[distributed]: a missing 'distributed' is found."""
    real = cli.metadata.distribution

    def without_distributed(name: str):
        if name.lower() == "distributed":
            raise cli.metadata.PackageNotFoundError(name)
        return real(name)

    monkeypatch.setattr(cli.metadata, "distribution", without_distributed)
    assert cli.missing_requirements("app") == ["distributed"]
    assert cli.missing_requirements("nonexistent-extra") == []
    assert cli.missing_requirements("app", dist="no-such-distribution") is None


def test_this_environment_has_every_extra() -> None:
    for extra in ("atlas", "app", "test", "bench", "dev"):
        assert cli.missing_requirements(extra) == [], extra


def _pyproject() -> dict:
    import tomllib

    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def _requirement_name(line: str) -> str:
    return re.match(r"[A-Za-z0-9][A-Za-z0-9._-]*", line).group(0)


def _closure(requirements: list[str]) -> set[str]:
    """Canonical names of the distributions these requirements install, through every dependency (installed
    metadata; extras of other distributions followed)."""
    from importlib import metadata

    seen: set[str] = set()
    todo = [(r, None) for r in requirements]
    while todo:
        line, _ = todo.pop()
        match = re.match(r"\s*([A-Za-z0-9][A-Za-z0-9._-]*)\s*(?:\[([^\]]*)\])?[^;]*(?:;(.*))?$", line)
        name, extras, _marker = match.groups()
        extras = {e.strip() for e in (extras or "").split(",") if e.strip()}
        key = _canonical(name) + "[" + ",".join(sorted(extras)) + "]"
        if key in seen:
            continue
        seen.add(key)
        if name.lower() == "asymslide":
            todo += [(r, None) for e in extras for r in _pyproject()["optional-dependencies"][e]]
            continue
        for req in metadata.requires(name) or []:
            marker = req.partition(";")[2]
            extra = re.search(r"""extra\s*==\s*["']([^"']+)["']""", marker)
            if extra is not None and extra.group(1) not in extras:
                continue
            if marker.strip() and extra is None and not _marker_applies(marker):
                continue
            todo.append((req, None))
    return {k.partition("[")[0] for k in seen} - {"asymslide"}


def _marker_applies(marker: str) -> bool:
    """Evaluate a dependency's environment marker (packaging is installed with the app's dependencies)."""
    from packaging.markers import Marker

    return Marker(marker).evaluate({"extra": ""})


def _canonical(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


#: the import names each layer may use, besides the standard library and the project's own packages
LAYER_FILES = {
    "core": ["model/**/*.py", "asymslide/__init__.py", "asymslide/__main__.py", "asymslide/warmup.py"],
    "atlas": ["atlas/*.py", "asymslide/cli.py"],
    "app": ["app/*.py", "asymslide/serve.py"],
}


def _imports(path: Path) -> set[str]:
    """The modules a module imports by absolute name (``from asymslide import model`` -> asymslide.model;
    relative imports stay in its own package)."""
    import ast

    names = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module == "asymslide":
            names |= {f"asymslide.{alias.name}" for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module)
    return names


def _top_level_imports(path: Path) -> set[str]:
    return {name.partition(".")[0] for name in _imports(path)}


def _third_party_imports(path: Path) -> set[str]:
    return _top_level_imports(path) - set(sys.stdlib_module_names) - {"asymslide", "__future__"}


def test_every_import_of_a_layer_is_installed_by_its_extra() -> None:
    """model/ needs only the core dependencies, the atlas engine only [atlas], the app only [app]."""
    from importlib.metadata import packages_distributions

    project = _pyproject()
    extras = project["optional-dependencies"]
    provided = {
        "core": _closure(project["dependencies"]),
        "atlas": _closure(project["dependencies"] + extras["atlas"]),
        "app": _closure(project["dependencies"] + extras["app"]),
    }
    providers = packages_distributions()
    problems = []
    for layer, patterns in LAYER_FILES.items():
        for path in sorted(p for pattern in patterns for p in ROOT.glob(pattern)):
            for module in sorted(_third_party_imports(path)):
                dists = {_canonical(d) for d in providers.get(module, [module])}
                if not dists & provided[layer]:
                    problems.append(f"{path.relative_to(ROOT)} imports {module} ({', '.join(sorted(dists))}), "
                                    f"not installed by the {layer} requirements")
    assert problems == []
    assert {_canonical(_requirement_name(r)) for r in project["dependencies"]} == {"numpy", "scipy", "numba"}


# ---------------------------------------------------------------------------------------------------------------
# the lock: one file for the .venv and the image
# ---------------------------------------------------------------------------------------------------------------

LOCK = ROOT / "requirements.lock"


def _locked() -> dict[str, str]:
    pins = {}
    for line in LOCK.read_text().splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        match = re.fullmatch(r"([A-Za-z0-9][A-Za-z0-9._-]*)==([^\s;]+)", line.strip())
        assert match is not None, f"not a plain pin usable as a pip constraint: {line!r}"
        pins[_canonical(match.group(1))] = match.group(2)
    return pins


def test_the_lock_pins_everything_every_extra_installs() -> None:
    project = _pyproject()
    everything = _closure(project["dependencies"] + [r for rs in project["optional-dependencies"].values()
                                                     for r in rs])
    pins = _locked()
    assert sorted(everything - set(pins)) == []
    assert "asymslide" not in pins and "pip" not in pins


def test_this_environment_runs_the_locked_versions() -> None:
    """make test runs against requirements.lock: every locked distribution installed here has its pinned version."""
    from importlib import metadata

    pins = _locked()
    installed = {_canonical(d.metadata["Name"]): d.version for d in metadata.distributions()}
    wrong = {name: (installed[name], pin) for name, pin in pins.items() if name in installed and installed[name] != pin}
    assert wrong == {}, "installed != locked (run make venv)"
    assert set(pins) <= set(installed)


#: the project's layers from the bottom up (ARCHITECTURE.md) and their folders: a module may import its own layer
#: and those below; "asymslide" is the package's own modules (the command line, the launcher) on top
LAYERS = {"model": "model", "atlas": "atlas", "app": "app", "asymslide": "asymslide"}


def _layer(module: str) -> str | None:
    """The layer an absolute module name belongs to (None: not the project's)."""
    parts = module.split(".")
    if parts[0] != "asymslide":
        return None
    return parts[1] if len(parts) > 1 and parts[1] in LAYERS else "asymslide"


def test_no_import_runs_back_up_a_layer() -> None:
    """model -> atlas -> app -> asymslide's command line: each imports only its own layer and those below it."""
    order = list(LAYERS)
    upward = []
    for level, (layer, folder) in enumerate(LAYERS.items()):
        allowed = set(order[:level + 1])
        for path in sorted((ROOT / folder).rglob("*.py")):
            if bad := {m for m in _imports(path) if (lay := _layer(m)) is not None and lay not in allowed}:
                upward.append(f"{path.relative_to(ROOT)} ({layer}) imports {', '.join(sorted(bad))}")
    assert upward == []


def test_the_project_is_imported_by_one_name_only() -> None:
    """Every import of the project's code says asymslide...: the folders model/, atlas/ and app/ are not import
    names (a user's model.py must not be shadowed, nor shadow ours)."""
    bare = [f"{path.relative_to(ROOT)} imports {', '.join(sorted(bad))}"
            for folder in (*LAYERS.values(), "tests", "benchmarks", ".ci")
            for path in sorted((ROOT / folder).rglob("*.py"))
            if (bad := _top_level_imports(path) & {"model", "app", "atlas", "atlas_engine"})]
    assert bare == []


def test_the_app_opens_atlases_only_through_the_store() -> None:
    """app/ never reads Zarr itself: xarray and zarr are the atlas layer's (asymslide.atlas.store opens atlases)."""
    readers = [f"{path.relative_to(ROOT)} imports {', '.join(sorted(bad))}"
               for path in sorted((ROOT / "app").rglob("*.py"))
               if (bad := _third_party_imports(path) & {"xarray", "zarr"})]
    assert readers == []


#: the folder of each import package of the project
PACKAGE_ROOTS = {f"asymslide.{sub}": ROOT / folder for sub, folder in SUBPACKAGES.items()}


def _module_file(base: Path, dotted: str) -> Path | None:
    """The module file of `dotted` (relative to the package folder `base`): a module or a package's __init__."""
    target = base.joinpath(*dotted.split(".")) if dotted else base
    return next((c for c in (target.with_suffix(".py"), target / "__init__.py") if c.is_file()), None)


def _from_base(path: Path, node) -> tuple[Path, str] | None:
    """(package folder, module path in it) of a ``from ... import`` of the project (None: not the project's)."""
    if node.level:
        base = path.parent
        for _ in range(node.level - 1):
            base = base.parent
        return base, node.module or ""
    top = next((name for name in PACKAGE_ROOTS if (node.module or "").startswith(name)), None)
    return None if top is None else (PACKAGE_ROOTS[top], node.module[len(top) + 1:])


def _module_imports(path: Path) -> set[Path]:
    """The project's modules that a module imports, at any depth of its code (an import inside a function is still
    a dependency: it only hides a cycle until the function runs)."""
    import ast

    found: set[Path | None] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module == "asymslide":
            found |= {_module_file(ROOT / SUBPACKAGES[a.name], "") for a in node.names if a.name in SUBPACKAGES}
        elif isinstance(node, ast.ImportFrom) and (where := _from_base(path, node)) is not None:
            base, module = where
            for alias in node.names:  # from . import sweep: the submodule, if there is one
                sub = _module_file(base, f"{module}.{alias.name}" if module else alias.name)
                found.add(sub if sub is not None else _module_file(base, module))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                top = next((name for name in PACKAGE_ROOTS if alias.name.startswith(name)), None)
                if top is not None:
                    found.add(_module_file(PACKAGE_ROOTS[top], alias.name[len(top) + 1:]))
    return {f for f in found if f is not None and f != path}


def _cycles(graph: dict[Path, set[Path]]) -> list[list[Path]]:
    """The import cycles of a graph (module -> modules it imports): the strongly connected components of more than
    one module (scipy's csgraph)."""
    from scipy.sparse import csr_array
    from scipy.sparse.csgraph import connected_components

    nodes = sorted(graph)
    at = {v: i for i, v in enumerate(nodes)}
    edges = [(at[v], at[w]) for v in nodes for w in graph[v] if w in at]
    rows, cols = zip(*edges, strict=True) if edges else ((), ())
    matrix = csr_array(([1] * len(edges), (rows, cols)), shape=(len(nodes), len(nodes)))
    _, labels = connected_components(matrix, directed=True, connection="strong")
    groups = [[v for v, label in zip(nodes, labels, strict=True) if label == k] for k in set(labels)]
    return sorted(g for g in groups if len(g) > 1)


def test_no_import_cycle_within_a_layer() -> None:
    """The modules of each layer import each other one way only (a package's ``__init__`` that gathers its modules
    is the top of its package, so a module importing it back is a cycle too)."""
    cycles = []
    for folder_name in (*SUBPACKAGES.values(), "asymslide"):
        folder = ROOT / folder_name
        graph = {path: _module_imports(path) & set(folder.rglob("*.py")) for path in folder.rglob("*.py")}
        cycles += [" -> ".join(str(p.relative_to(ROOT)) for p in cycle) for cycle in _cycles(graph)]
    assert cycles == []


def _private_names_crossing(path: Path, package: Path, root: Path = ROOT) -> list[str]:
    """The underscored names a module takes from another module of the project: imported (``from m import _x``) or
    read as an attribute of a module it imported (``m._x``). Importing a private module or package itself (``from .
    import _kernels``) is not counted in model/ (``package``), whose private parts are its own."""
    import ast

    tree = ast.parse(path.read_text(), str(path))
    modules: set[str] = set()  # names bound to project modules in this file
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("asymslide")):
            base = path.parent
            for _ in range(max(node.level - 1, 0)):
                base = base.parent
            for a in node.names:
                sub = base.joinpath(*(node.module or "").split(".")) / a.name if node.level else None
                is_module = sub is not None and (sub.with_suffix(".py").exists() or sub.is_dir())
                if is_module:
                    modules.add(a.asname or a.name)
                if a.name.startswith("_") and not a.name.startswith("__"):
                    if not (is_module and package in path.parents):
                        found.append(f"{path.relative_to(root)}: {node.module} {a.name}")
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in modules
                and node.attr.startswith("_") and not node.attr.startswith("__")):
            found.append(f"{path.relative_to(root)}: {node.value.id}.{node.attr}")
    return found


def test_no_module_uses_an_underscored_name_of_another_module() -> None:
    """A module of model/, atlas/, app/ or asymslide/ takes no underscored name from another module of the project
    (imported or as a module's attribute): what one module needs of another is that module's API. The model's
    private packages (``_kernels``, ``_roots``) and modules (``_validate``) are imported whole by the model, and
    their own names are not underscored; the other layers import none of them."""
    private = []
    for folder in ("model", "atlas", "app", "asymslide"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            private += _private_names_crossing(path, ROOT / "model")
    assert private == []


def test_the_private_name_check_sees_both_forms(tmp_path: Path) -> None:
    """The check above finds ``from .m import _x`` and ``m._x``, and in the model allows ``from . import _kernels``."""
    pkg = tmp_path / "model"
    (pkg / "_kernels").mkdir(parents=True)
    for name in ("__init__.py", "_kernels/__init__.py", "stability.py", "sliding.py"):
        (pkg / name).write_text("")
    probe = pkg / "_probe_private_names.py"
    probe.write_text("from . import _kernels, stability\nfrom .sliding import _hidden\nx = stability._grid\n")
    found = _private_names_crossing(probe, pkg, tmp_path)
    assert found == ["model/_probe_private_names.py: sliding _hidden", "model/_probe_private_names.py: stability._grid"]
