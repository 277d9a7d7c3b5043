"""The package's layout rules (docs/architecture.md), read from the source as it stands.

Every ``import`` counts, the ones inside functions too (the command modules import their implementation
when they run): the rules are about what a module may use, not about when it loads it. Each test names
the offending files and lines, so a failure says where to look.
"""
import ast
import collections
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "bearingsim"

#: longest function outside the compiled kernels [lines, from ``def`` to its last line]
MAX_FUNCTION_LINES = 80
#: functions allowed longer, each with its stated reason (none today)
LONG_FUNCTIONS: dict[str, str] = {}


def _modules(package: Path = PACKAGE) -> dict[str, Path]:
    """Dotted module name -> source file, for every module of the package (a package is its __init__)."""
    mods = {}
    for path in sorted(package.rglob("*.py")):
        parts = list(path.relative_to(package.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        mods[".".join(parts)] = path
    return mods


def _imports(package: Path = PACKAGE):
    """(importer, imported, line) for every import of a module of the package by another, and
    {third-party top-level name: [(importer, line), ...]}. ``from bearingsim.x import y`` names the
    module ``bearingsim.x.y`` when that is a module, else ``bearingsim.x``."""
    mods = _modules(package)
    internal, external = [], collections.defaultdict(list)
    for name, path in mods.items():
        here = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = here.split(".")
                    parts = parts[:len(parts) - node.level + 1]
                    base = ".".join(parts + ([node.module] if node.module else []))
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in node.names]
            else:
                continue
            for target in targets:
                top = target.partition(".")[0]
                if top != package.name:
                    external[top].append((name, node.lineno))
                    continue
                while target not in mods and "." in target:
                    target = target.rpartition(".")[0]
                if target in mods and target != name:
                    internal.append((name, target, node.lineno))
                for pkg in _enclosing_packages(target, package.name):  # Python runs them first
                    if pkg in mods and pkg != name and not name.startswith(pkg + "."):
                        internal.append((name, pkg, node.lineno))
    return internal, external


def _enclosing_packages(target: str, root: str) -> list[str]:
    """The subpackages that Python imports before the module ``target`` (``a.b`` for ``a.b.c``): importing
    ``bearingsim.multibody.core`` runs ``bearingsim/multibody/__init__.py``. The root package is left out: it
    encloses every module, so Python has loaded it before any import of its own, and it imports the package's
    modules only in its functions, when called (PEP 562)."""
    parts = target.split(".")
    return [".".join(parts[:k]) for k in range(2, len(parts)) if parts[0] == root]


def _cycles(edges) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    graph = collections.defaultdict(set)
    for a, b, _ in edges:
        graph[a].add(b)
    index, low, stack, on_stack, found = {}, {}, [], set(), []
    for start in sorted(set(graph) | {b for bs in graph.values() for b in bs}):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    comp = []
                    while True:
                        m = stack.pop()
                        on_stack.discard(m)
                        comp.append(m)
                        if m == node:
                            break
                    if len(comp) > 1:
                        found.append(sorted(comp))
            elif child not in index:
                index[child] = low[child] = len(index)
                stack.append(child)
                on_stack.add(child)
                work.append((child, iter(sorted(graph[child]))))
            elif child in on_stack:
                low[node] = min(low[node], index[child])
    return found


def _where(edges, pred) -> list[str]:
    return [f"{a} imports {b} (line {line})" for a, b, line in edges if pred(a, b)]


def _in(name: str, *prefixes: str) -> bool:
    return any(name == p or name.startswith(p + ".") for p in prefixes)


@pytest.fixture(scope="module")
def imports():
    return _imports()


def test_no_two_modules_import_each_other_even_through_others(imports):
    """A lower layer never imports a higher one: the import graph has no circle, so every module stands
    above all it imports."""
    cycles = _cycles(imports[0])
    assert not cycles, "modules that import each other: " + "; ".join(" <-> ".join(c) for c in cycles)


def test_a_model_never_sees_the_scenario_file_the_archive_or_what_runs_it(imports):
    """docs/architecture.md: a model gets ``Parameters`` and a sink and returns a result; the model packages
    hold models only."""
    above = ("bearingsim.scenario", "bearingsim.ranges", "bearingsim.archive", "bearingsim.outputs",
             "bearingsim.simulation", "bearingsim.plausibility", "bearingsim.sweeps", "bearingsim.studies",
             "bearingsim.reports", "bearingsim.animation", "bearingsim.tables", "bearingsim.keys",
             "bearingsim.compare")
    bad = _where(imports[0], lambda a, b: _in(a, "bearingsim.reduced", "bearingsim.multibody")
                 and (_in(b, *above) or b.startswith("bearingsim.cli")))
    assert not bad, "; ".join(bad)


def test_the_library_never_imports_the_command_line(imports):
    """Commands are thin subcommands over the API: only command modules import command modules."""
    commands = ("bearingsim.cli", "bearingsim.cli_common", "bearingsim.cli_sweep", "bearingsim.cli_wear",
                "bearingsim.cli_sensitivity", "bearingsim.cli_animate", "bearingsim.__main__")
    bad = _where(imports[0], lambda a, b: _in(b, *commands) and not _in(a, *commands))
    assert not bad, "; ".join(bad)


def test_only_the_command_line_imports_the_package_itself(imports):
    """``bearingsim/__init__.py`` is the Python API, a facade over the orchestration, the studies and the
    reports: a module below it that imports the package itself (``from bearingsim import name`` of a name
    that is no module) depends on everything the facade does. Subpackages found their submodules through
    it (``from bearingsim import _submodule``); that helper is the leaf module ``bearingsim/_lazy.py``."""
    commands = ("bearingsim.cli", "bearingsim.__main__")
    bad = _where(imports[0], lambda a, b: b == "bearingsim" and a not in commands)
    assert not bad, "; ".join(bad)


@pytest.mark.parametrize(("package", "users"), [
    ("h5py", {"bearingsim.archive"}),  # the only h5py user
    ("pymunk", {"bearingsim.multibody.chipmunk", "bearingsim.multibody.loop", "bearingsim.multibody.scene"}),
    ("distributed", {"bearingsim.sweeps.engines"}),  # the optional cluster extra
    ("dask", {"bearingsim.sweeps.engines"}),
    ("jinja2", {"bearingsim.reports"}),
])
def test_a_third_party_package_is_used_by_its_own_modules_alone(imports, package, users):
    got = {name for name, _ in imports[1].get(package, [])}
    assert got <= users, f"{package} imported by {sorted(got - users)}"


def test_pandas_and_xarray_are_imported_by_the_frames_module_alone():
    """The ``frames`` extra: pandas and xarray are loaded by ``bearingsim/frames.py`` through importlib,
    named nowhere else (so bearingsim works without them)."""
    bad = []
    for name, path in _modules().items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            strings = [node.value] if isinstance(node, ast.Constant) and isinstance(node.value, str) else []
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
            names += [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            for text in names + [s for s in strings if s in ("pandas", "xarray")]:
                if text.partition(".")[0] in ("pandas", "xarray") and name != "bearingsim.frames":
                    bad.append(f"{name}:{node.lineno}")
    assert not bad, "pandas or xarray named in " + ", ".join(bad)


def _is_compiled_kernel(fn: ast.FunctionDef) -> bool:
    for deco in fn.decorator_list:
        target = deco.func if isinstance(deco, ast.Call) else deco
        name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
        if name in ("njit", "jit"):
            return True
    return False


def test_no_function_is_longer_than_80_lines_outside_the_compiled_kernels():
    """A compiled kernel may be long (numba inlines and types one body; splitting it costs calls in the
    step loop); any other function longer than ``MAX_FUNCTION_LINES`` needs its reason in
    ``LONG_FUNCTIONS``."""
    long = []
    for name, path in _modules().items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and not _is_compiled_kernel(node):
                lines = node.end_lineno - node.lineno + 1
                key = f"{name}.{node.name}"
                if lines > MAX_FUNCTION_LINES and key not in LONG_FUNCTIONS:
                    long.append(f"{key} ({path.relative_to(ROOT)}:{node.lineno}): {lines} lines")
    assert not long, "; ".join(long)


# The checks above must be able to fail: each is run on a small package made to break it.

def _package(tmp_path, files: dict[str, str]) -> Path:
    pkg = tmp_path / "bearingsim"
    for rel, text in files.items():
        (pkg / rel).parent.mkdir(parents=True, exist_ok=True)
        (pkg / rel).write_text(text)
    return pkg


def test_a_circle_through_a_function_level_import_is_found(tmp_path):
    pkg = _package(tmp_path, {"__init__.py": "", "a.py": "from bearingsim import b\n",
                              "b.py": "def f():\n    from bearingsim.c import g\n",
                              "c.py": "import bearingsim.a\n", "d.py": "from bearingsim import a\n"})
    edges, _ = _imports(pkg)
    assert _cycles(edges) == [["bearingsim.a", "bearingsim.b", "bearingsim.c"]]


def test_importing_a_subpackage_s_module_runs_the_subpackage_first(tmp_path):
    """``from bearingsim.m.core import f`` runs ``m/__init__.py`` before ``m/core.py``: a module that imports
    ``m.core`` while ``m/__init__.py`` imports it (through others) is a circle, though ``m.core`` imports
    nothing of it; the root package, loaded before any of its modules, is not such an edge."""
    pkg = _package(tmp_path, {"__init__.py": "", "a.py": "def f():\n    from bearingsim.m.core import g\n",
                              "m/__init__.py": "from bearingsim import b\n", "m/core.py": "from . import leaf\n",
                              "m/leaf.py": "", "b.py": "import bearingsim.a\n"})
    edges, _ = _imports(pkg)
    assert ("bearingsim.a", "bearingsim.m", 2) in edges
    assert ("bearingsim.m.core", "bearingsim.m", 1) not in edges  # a module's own package is being loaded
    assert _cycles(edges) == [["bearingsim.a", "bearingsim.b", "bearingsim.m"]]


def test_a_relative_import_and_a_name_that_is_not_a_module_are_read_as_python_reads_them(tmp_path):
    pkg = _package(tmp_path, {"__init__.py": "X = 1\n", "m/__init__.py": "from .core import f\n",
                              "m/core.py": "from .. import X\nfrom ..m import core\nimport numpy as np\n"})
    edges, external = _imports(pkg)
    assert sorted((a, b) for a, b, _ in edges) == [("bearingsim.m", "bearingsim.m.core"),
                                                   ("bearingsim.m.core", "bearingsim")]
    assert external == {"numpy": [("bearingsim.m.core", 3)]}


# --- a run computes its set-up once ------------------------------------------------------------------
def _calls_during(fn, names):
    """Run ``fn()`` and count the calls of the package's Python functions named in ``names``
    ({"module/file.py:function": n}); the compiled kernels are not Python frames and not counted."""
    import sys

    counts = collections.Counter()

    def profile(frame, event, arg):
        if event == "call" and frame.f_code.co_name in names:
            path = Path(frame.f_code.co_filename)
            if PACKAGE in path.parents:
                counts[f"{path.relative_to(PACKAGE).as_posix()}:{frame.f_code.co_name}"] += 1

    previous = sys.getprofile()
    sys.setprofile(profile)
    try:
        result = fn()
    finally:
        sys.setprofile(previous)
    return result, counts


@pytest.mark.slow
@pytest.mark.parametrize("scenario, steps", [("multibody_6000rpm.toml", {"multibody/core.py:choose_dt": 1}),
                                             ("paper_3000rpm.toml", {})])
def test_bearingsim_run_builds_its_parameters_and_its_time_step_once(tmp_path, scenario, steps):
    """`bearingsim run` (its checks, the dry-run's checks it shares, the model, the archive, the
    plausibility checks) builds the SI parameters once (``Scenario.parameters``, frozen) and the whole
    bearing chooses its time step once (``multibody.core.choose_dt``): the set-up is computed once per
    run and handed down. ``--no-plots``: the figures are drawn from the archive read back, a second
    scenario with parameters of its own."""
    from bearingsim.cli import main

    root = ROOT / "scenarios" / scenario
    code, counts = _calls_during(
        lambda: main(["run", str(root), "--set", "numerics.rotations=1", "-o", str(tmp_path / "r.h5"), "--no-plots", "-q"]),
        {"from_scenario", "choose_dt"})
    assert code == 0
    assert counts == collections.Counter({"parameters.py:from_scenario": 1, **steps})


#: what the checkout holds at its top level (the package, its scenarios, tests, docs, benchmarks and CI):
#: anything else committed is a stray
TOP_LEVEL = {".ci", ".gitignore", "CHANGELOG.md", "README.md", "bearingsim", "benchmarks", "docs", "outputs",
             "pyproject.toml", "scenarios", "tests"}
#: the kinds of file a run writes; committed only as the docs' pictures (docs/) and the tests' data (tests/data/)
RESULT_SUFFIXES = {".h5", ".png", ".gif", ".html", ".csv", ".nc"}


def _tracked_files() -> list[str]:
    import shutil
    import subprocess

    if not (ROOT / ".git").exists() or shutil.which("git") is None:
        pytest.skip("not a git checkout (an installed copy has no committed files to check)")
    # safe.directory: git refuses a checkout another user owns (a container's, a mounted CI volume's)
    out = subprocess.run(["git", "-c", f"safe.directory={ROOT}", "-C", str(ROOT), "ls-files", "-z"],
                         capture_output=True, check=True)
    return [f for f in out.stdout.decode().split("\0") if f]


def test_the_checkout_commits_no_results_and_nothing_beside_its_layout():
    """A run's archive or figure committed by mistake (outside docs/ and tests/data/) is found, and so is
    a top-level entry the layout does not have."""
    files = _tracked_files()
    strays = sorted({f.split("/")[0] for f in files} - TOP_LEVEL)
    results = [f for f in files if Path(f).suffix.lower() in RESULT_SUFFIXES
               and not f.startswith(("docs/", "tests/data/"))]
    assert not strays, f"committed outside the layout: {strays}"
    assert not results, f"results committed (outputs/ is for them, ignored by git): {results}"
    assert [f for f in files if f.startswith("outputs/")] == ["outputs/.gitkeep"]


def test_the_package_is_typed_and_its_public_functions_are_annotated():
    """PEP 561: ``bearingsim/py.typed`` marks the package as typed and is installed with it (package data); every
    function of ``bearingsim.__all__`` annotates its parameters and its return, and the annotations name what
    exists (resolved with the names the module imports for type checking only)."""
    import inspect
    import tomllib
    import typing

    import bearingsim

    assert (PACKAGE / "py.typed").is_file()
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["bearingsim"]
    assert "py.typed" in data, data
    checking = {}  # the names imported under `if TYPE_CHECKING:` in bearingsim/__init__.py
    for node in ast.parse((PACKAGE / "__init__.py").read_text()).body:
        if isinstance(node, ast.If) and ast.unparse(node.test) == "TYPE_CHECKING":
            exec(compile(ast.Module(node.body, []), "<TYPE_CHECKING>", "exec"), checking)
    functions = [n for n in bearingsim.__all__ if inspect.isfunction(getattr(bearingsim, n))]
    assert {"load_scenario", "run", "load", "animate", "sensitivity", "uncertainty", "report"} <= set(functions)
    for name in functions:
        f = getattr(bearingsim, name)
        sig = inspect.signature(f)
        bare = [p for p in sig.parameters if sig.parameters[p].annotation is inspect.Parameter.empty]
        assert not bare and sig.return_annotation is not inspect.Signature.empty, (name, bare, str(sig))
        hints = typing.get_type_hints(f, globalns={**vars(bearingsim), **checking})
        assert set(hints) == {*sig.parameters, "return"}, (name, hints)
