"""The user's pages stand alone: every relative link resolves inside the repository, and nothing the
code, preset, scenarios or docs rely on points outside it."""
import re

from .conftest import ROOT
from .forked_cli import pythonpath as _path

PAGES = [ROOT / "README.md", ROOT / "CHANGELOG.md", *sorted((ROOT / "docs").glob("*.md"))]


def test_every_relative_link_resolves():
    broken = []
    for page in PAGES:
        for target in re.findall(r"\]\(([^)\s]+)\)", page.read_text()):
            if re.match(r"[a-z]+:", target) or target.startswith("#"):
                continue
            path = (page.parent / target.split("#", 1)[0]).resolve()
            if not path.exists():
                broken.append(f"{page.relative_to(ROOT)} -> {target}")
    assert not broken, broken


def test_nothing_cites_a_file_outside_the_repository():
    roots = [ROOT / "bearingsim", ROOT / "scenarios", ROOT / "docs", ROOT / "benchmarks", ROOT / "tests"]
    files = [p for r in roots for p in r.rglob("*") if p.suffix in {".py", ".toml", ".md"}]
    files += [ROOT / "README.md"]
    pattern = re.compile(r"PHYSICS\.md|shared/(?:seed|tools|PHYSICS)|\.\./shared")
    offenders = [str(p.relative_to(ROOT)) for p in files
                 if p.name != "test_docs.py" and pattern.search(p.read_text(errors="replace"))]
    assert not offenders, offenders


def test_readme_is_a_users_page():
    """The README says what bearingsim is, shows it, starts it, and points onward (docs/ for the rest)."""
    text = (ROOT / "README.md").read_text()
    for heading in ("## Quick start", "## What it finds", "## Where to go next"):
        assert heading in text
    assert "![" in text                                   # a picture
    assert not re.search(r"\bissue \d+", text, re.I)       # no development log
    assert len(text.splitlines()) < 150


def test_the_pages_carry_no_development_references():
    """The README and docs/ are the users' pages: no issue numbers of the development log (docs/reliability.md's
    heading, written by tests/test_reliability.py's ``write_doc``, ended "(issue 14)"), and no records of
    what a command did before it was mended ("Was: ...", "(was: ...)": 36 of them in docs/reliability.md);
    that history is in CHANGELOG.md."""
    pattern = re.compile(r"\bissue \d+|\(issue\b|\bwas: ", re.I)
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    offenders = [f"{p.relative_to(ROOT)}:{i + 1}" for p in pages
                 for i, line in enumerate(p.read_text().splitlines()) if pattern.search(line)]
    assert not offenders, offenders


def test_help_texts_and_scenarios_carry_no_development_references():
    """Users read the help texts, module docstrings and scenario files: no issue numbers, no pointers
    into a README section that is not there."""
    files = [*(ROOT / "bearingsim").rglob("*.py"), *(ROOT / "scenarios").rglob("*.toml")]
    pattern = re.compile(r"\bissue \d+|\(issue\b|README: ", re.I)
    offenders = [f"{p.relative_to(ROOT)}:{i + 1}" for p in files
                 for i, line in enumerate(p.read_text().splitlines()) if pattern.search(line)]
    assert not offenders, offenders


def test_scenario_files_cite_pages_and_sections_that_exist():
    """A scenario file's comment that points to a page (``docs/sweeps.md``, ``README``) names one that
    exists, and a quoted section (``docs/sweeps.md, "Many cheap cases, measured"``) is a heading or a
    bold paragraph of that page: map_speed_clearance.toml cited a README section "Sweeps" that the
    README does not have."""
    cite = re.compile(r'(README(?:\.md)?|docs/[\w.-]+\.md)(?:, "([^"]+)")?')
    broken = []
    for p in sorted((ROOT / "scenarios").rglob("*.toml")):
        for i, line in enumerate(p.read_text().splitlines()):
            if not line.lstrip().startswith("#"):
                continue
            for page, section in cite.findall(line):
                path = ROOT / ("README.md" if page.startswith("README") else page)
                where = f"{p.relative_to(ROOT)}:{i + 1}: {page}"
                if not path.is_file():
                    broken.append(f"{where}: no such page")
                    continue
                if section:
                    text = path.read_text()
                    if not re.search(rf"^#+ .*{re.escape(section)}|\*\*{re.escape(section)}", text, re.M):
                        broken.append(f"{where}: no section {section!r}")
    assert not broken, broken


def test_usage_key_table_lists_every_section_and_key():
    """docs/usage.md's table of scenario keys has a row for every section of a scenario and names every
    key in it (``bearingsim keys``): it lacked ``[output]`` and ``[ranges.*]``."""
    from bearingsim.keys import list_keys

    text = (ROOT / "docs" / "usage.md").read_text()
    table = text[text.index("| section | keys |"):]
    rows = {}
    for line in table.splitlines():
        if not line.startswith("|"):
            break
        cells = line.split("|")
        rows[cells[1].strip()] = cells[2]
    missing = []
    for info in list_keys():
        section, _, name = info.key.rpartition(".")
        if not section:  # a top-level key, or the [ranges.<section>.<key>] tables
            row = "`[ranges.<section>.<key>]`" if name == "ranges" else "top level"
            if row not in rows or (name != "ranges" and f"`{name}`" not in rows[row]):
                missing.append(info.key)
        elif f"`{name}`" not in rows.get(f"`[{section}]`", ""):
            missing.append(info.key)
    assert not missing, missing


def test_every_dotted_name_the_pages_give_resolves_after_a_plain_import():
    """The pages name ``bearingsim.sweeps.read_map``, ``bearingsim.animation.has_motion``,
    ``bearingsim.outputs.ArchiveWriteError``, ``bearingsim.studies.life.read_life``, ...: each is reached
    by attributes alone after ``import bearingsim``, in a fresh interpreter (in this one the tests have
    imported most modules already). Before the package gave its submodules on first use (PEP 562),
    26 of the 35 names raised AttributeError."""
    import json
    import os
    import subprocess
    import sys

    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    names = sorted({m for page in pages for m in re.findall(r"\bbearingsim(?:\.[A-Za-z_]\w*)+", page.read_text())})
    assert len(names) > 30 and "bearingsim.studies.life.read_life" in names
    probe = ("import functools, json, sys\n"
             "import bearingsim\n"
             "bad = []\n"
             "for name in json.loads(sys.argv[1]):\n"
             "    try:\n"
             "        functools.reduce(getattr, name.split('.')[1:], bearingsim)\n"
             "    except AttributeError as exc:\n"
             "        bad.append(f'{name}: {exc}')\n"
             "print(json.dumps(bad))\n")
    env = {**os.environ, "PYTHONPATH": _path()}
    out = subprocess.run([sys.executable, "-c", probe, json.dumps(names)], capture_output=True, text=True, env=env,
                         cwd=ROOT, timeout=300)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout) == []


def test_the_package_gives_its_submodules_on_first_use_and_no_other_name():
    import bearingsim

    assert {"outputs", "animation", "studies", "sweeps", "reduced", "multibody", "wear"} <= set(dir(bearingsim))
    assert {"life", "crosscheck", "fig9"} <= set(dir(bearingsim.studies))
    for package, name in ((bearingsim, "no_such_module"), (bearingsim.studies, "no_such_study"),
                          (bearingsim.sweeps, "no_such_part"), (bearingsim, "__wrapped__")):
        try:
            getattr(package, name)
        except AttributeError as exc:
            assert f"has no attribute {name!r}" in str(exc)
        else:
            raise AssertionError(f"{package.__name__}.{name} resolved")


def _code_spans(page) -> list[str]:
    """The code of ``page`` in order: each line of its code blocks (fenced, or indented by 4 spaces; ``\\``
    continues a line, `` #`` starts a comment) and each inline code span."""
    text = page.read_text()
    fences = re.compile(r"^```[^\n]*\n(.*?)^```", re.S | re.M)
    rest = fences.sub(lambda m: " " * len(m.group(0)), text)  # the prose, at the same positions
    blocks = [m for m in fences.finditer(text)] + [m for m in re.finditer(r"^ {4}\S.*\n(?:^ {4}.*\n)*", rest, re.M)]
    spans = []  # (position, code)
    for m in blocks:
        joined = re.sub(r"\\\n\s*", " ", m.group(1) if m.re is fences else m.group(0))
        spans += [(m.start(), line.split(" #")[0]) for line in joined.splitlines()]
    spans += [(m.start(), " ".join(m.group(1).split())) for m in re.finditer(r"`([^`]+)`", rest)]
    return [code for _, code in sorted(spans, key=lambda s: s[0])]


def _run_commands(page):
    """Every ``bearingsim run ...`` command of ``page`` in order (:func:`_code_spans`), as argument lists
    after ``run``."""
    import shlex

    out = []
    for span in _code_spans(page):
        for cmd in re.findall(r"bearingsim run (.*)", span):
            try:
                out.append(shlex.split(cmd))
            except ValueError:  # an unbalanced quote in prose: not a command
                continue
    return out


def _options(args):
    """(scenario, [--set values], -o value or None, flags) of a ``bearingsim run`` argument list."""
    scenario, sets, out, flags = None, [], None, set()
    it = iter(args)
    for a in it:
        if a == "--set":
            sets.append(next(it, ""))
        elif a in ("-o", "--output"):
            out = next(it, None)
        elif a.startswith("-"):
            flags.add(a)
        elif scenario is None:
            scenario = a
    return scenario, sets, out, flags


def test_every_run_example_with_set_writes_an_archive_of_its_own():
    """`bearingsim run S --set K=V` writes outputs/<name>.h5 like `bearingsim run S`, and a run of another
    scenario there is refused ("holds the run of a different scenario"): usage.md's second command was
    refused after its first, and animation.md's three `run x.toml --set ...` one after the other. Every
    example that sets a key names its own archive with -o."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    pages.remove(ROOT / "docs" / "reliability.md")  # its commands are bad input, each in an empty folder
    found, missing = 0, []
    for page in pages:
        for args in _run_commands(page):
            scenario, sets, out, flags = _options(args)
            if sets and "--dry-run" not in flags:
                found += 1
                if out is None:
                    missing.append(f"{page.name}: bearingsim run {' '.join(args)}")
    assert found >= 9 and not missing, missing


def test_the_sweep_examples_of_the_pages_do_not_share_a_folder():
    """A sweep into a folder that holds another sweep is refused; the README's speed sweep, docs/sweeps.md's
    product sweep and docs/usage.md's (which gave no -o) all went to outputs/sweep, so whichever a reader
    ran second was refused. Across the README and docs/, two sweep examples that write one folder are the
    same sweep (the same scenario, --param, --set and sweep file; -j, -q, --scheduler aside)."""
    import shlex

    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    pages.remove(ROOT / "docs" / "reliability.md")  # its commands are bad input, each in an empty folder
    engine = {"-j", "--jobs", "--scheduler"}
    by_folder, clashes = {}, []
    for page in pages:
        for span in _code_spans(page):
            for cmd in re.findall(r"bearingsim sweep (.*)", span):
                try:
                    args = shlex.split(cmd)
                except ValueError:
                    continue
                if not args or not (ROOT / args[0]).is_file():
                    continue  # a placeholder (SCENARIO, FILE)
                out, what, it = "outputs/sweep", [], iter(args)
                for a in it:
                    if a in ("-o", "--output"):
                        out = next(it, out)
                    elif a in engine:
                        next(it, None)
                    elif a not in ("-q", "--quiet", "--no-plots"):
                        what.append(a)
                seen = by_folder.setdefault(out, (tuple(what), page.name))
                if seen[0] != tuple(what):
                    clashes.append(f"{out}: {seen[1]} and {page.name}")
    assert len(by_folder) >= 4 and not clashes, clashes


def test_the_run_examples_of_a_page_run_in_order():
    """Within each page, in order, no `bearingsim run` example writes an archive that an earlier one wrote
    for another resolved scenario (it would be refused without --force)."""
    from bearingsim.scenario import load_scenario

    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    pages.remove(ROOT / "docs" / "reliability.md")  # its commands are bad input, each in an empty folder
    refused, checked = [], 0
    for page in pages:
        written = {}
        for args in _run_commands(page):
            scenario, sets, out, flags = _options(args)
            if scenario is None or "--dry-run" in flags or not (ROOT / scenario).is_file():
                continue  # a placeholder (x.toml, SCENARIO, <rpm>): checked by the test above
            sc = load_scenario(ROOT / scenario, sets)
            target = out or f"outputs/{sc.name}.h5"
            if target in written and written[target] != sc and "--force" not in flags:
                refused.append(f"{page.name}: bearingsim run {' '.join(args)}")
            written[target] = sc
            checked += 1
    assert checked >= 10 and not refused, refused


def test_example_outputs_go_where_git_ignores_them():
    """docs/wear.md's examples wrote into out/ (-o out/wear_test.h5, -o out/life), a folder a checkout does
    not ignore; every example's -o in the README and docs/ is under outputs/ (ignored by .gitignore), a
    file in the current folder, or a placeholder (DIR, FILE.html, OUT.h5, {tmp}/...)."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    assert "outputs/*" in (ROOT / ".gitignore").read_text().split()
    outside, seen = [], 0
    for page in pages:
        for span in _code_spans(page):
            for target in re.findall(r"(?:^|\s)(?:-o|--output) (\S+)", span):
                seen += 1
                first = target.split("/")[0]
                if "/" in target and first not in ("outputs", "") and not (first.isupper() or first.startswith("{")):
                    outside.append(f"{page.name}: -o {target}")
    assert seen > 20 and not outside, outside


def test_the_quick_start_says_both_models_compile_on_their_first_run():
    """The README's quick start gave the main job's first-run compile as if only the multibody model
    compiled; the reduced model's first run compiles its event solver too. It names the benchmark that
    measures both (a first run from an empty kernel cache) and the time of each."""
    text = (ROOT / "README.md").read_text()
    start = " ".join(text[text.index("## Quick start"):text.index("## What it finds")].split())
    assert "The first run of each model compiles" in start
    assert "python -m benchmarks.compile_time" in start
    assert re.search(r"\d+(\.\d+)? s for the main job's and \d+(\.\d+)? s for the reduced model's", start), start


def test_every_file_an_example_reads_is_one_an_example_writes():
    """An example that reads an archive or a folder under outputs/ (``bearingsim inspect|show|plot|rerun|
    compare|table|animate|report|wear``, ``bearingsim.load``, ``index_dataframe``, ``read_map``,
    ``open_dataset``) reads one that a command or snippet of the README or docs/ writes (``-o``, a run's
    default ``outputs/<name>.h5``, sweep's ``outputs/sweep``, validate's ``outputs/validate``, ``save``,
    ``run_studies``, ``sensitivity``, ``uncertainty``), or a file in it: usage.md compared
    outputs/a.h5 with outputs/b.h5 and dataframes.md loaded outputs/multibody_3000rpm.h5, which nothing
    wrote (file not found)."""
    import shlex

    from bearingsim.scenario import load_scenario

    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    pages.remove(ROOT / "docs" / "reliability.md")  # its commands are bad input, each in an empty folder
    takes_value = {"--set", "--param", "--rotations", "--speeds", "-j", "--jobs", "--scheduler", "--keys", "--step",
                   "--samples", "--seed", "--limit", "--stages", "--mapping", "--columns", "--animation",
                   "--exaggerate", "--fps", "--hours", "--archives", "--preset", "--rig-rotations"}
    readers = {"inspect", "show", "plot", "rerun", "compare", "table", "animate", "report", "wear"}
    default_folder = {"sweep": "outputs/sweep", "validate": "outputs/validate"}
    written, reads = set(), []
    for page in pages:
        text = page.read_text()
        snippets = [m.group(1) for m in re.finditer(r"^```python\n(.*?)^```", text, re.S | re.M)]
        for span in _code_spans(page) + snippets:
            for cmd, rest in re.findall(r"bearingsim ([a-z]+) ?([^|&;>#]*)", span):
                try:
                    args = shlex.split(rest)
                except ValueError:
                    continue
                out, positional, it = None, [], iter(args)
                for a in it:
                    if a in ("-o", "--output"):
                        out = next(it, None)
                    elif a in takes_value:
                        next(it, None)
                    elif not a.startswith("-"):
                        positional.append(a)
                if cmd in readers:
                    reads += [(page.name, p) for p in positional if p.startswith("outputs/")]
                if out:
                    written.add(out.rstrip("/"))
                elif cmd == "run" and positional and (ROOT / positional[0]).is_file():
                    sets = [args[i + 1] for i, a in enumerate(args[:-1]) if a == "--set"]
                    written.add(f"outputs/{load_scenario(ROOT / positional[0], sets).name}.h5")
                elif cmd in default_folder:
                    written.add(default_folder[cmd])
            for m in re.finditer(r'(?:load|index_dataframe|read_map|open_dataset)\("(outputs/[^"]+)"', span):
                reads.append((page.name, m.group(1)))
            for m in re.finditer(r'(?:save\(|run_studies\(\[[^]]*\],|sensitivity\(sc,|uncertainty\(sc, \d+,)\s*'
                                 r'"(outputs/[^"]+)"', span):
                written.add(m.group(1))
    unwritten = [f"{page}: {path}" for page, path in reads
                 if not any(path == w or path.startswith(w + "/") for w in written)]
    assert len(reads) > 20 and not unwritten, unwritten


def test_every_command_and_option_the_pages_name_exists():
    """Each ``bearingsim <command> ...`` in the code of the README and docs/ (a command line or an inline
    span; ``run|sweep`` names two) names a subcommand of the parser, and each option it gives (``--set``,
    ``-j``, ``[--mapping uniform]``) is one that subcommand accepts."""
    import argparse

    from bearingsim.cli import build_parser

    options = {}
    for action in build_parser()._actions:
        if isinstance(action, argparse._SubParsersAction):
            options = {name: set(sub._option_string_actions) for name, sub in action.choices.items()}
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    bad, seen = [], 0
    for page in pages:
        for span in _code_spans(page):
            for m in re.finditer(r"\bbearingsim ((?:[a-z]+\|)*[a-z]+)\b((?: +[^ ]+)*)", span):
                for command in m.group(1).split("|"):
                    seen += 1
                    if command not in options:
                        bad.append(f"{page.name}: bearingsim {command}: no such command")
                        continue
                    for token in m.group(2).split():
                        for flag in re.split(r"[|\[\]]", token):
                            flag = flag.split("=")[0].rstrip(")")  # a quoted message's "(... --help)"
                            if re.match(r"--?[A-Za-z]", flag) and flag not in options[command]:
                                bad.append(f"{page.name}: bearingsim {command} {flag}: no such option")
    assert seen > 100 and not bad, bad


def test_architecture_names_every_benchmark_script():
    """docs/architecture.md says what each script of benchmarks/ is for; a script it does not name is one a
    reader of the layout cannot find (nine were missing)."""
    text = (ROOT / "docs" / "architecture.md").read_text()
    scripts = sorted(p.name for p in (ROOT / "benchmarks").glob("*.py") if p.name != "__init__.py")
    assert scripts and [s for s in scripts if f"`{s}`" not in text] == []


def test_commands_page_names_every_default_column_of_table():
    """`bearingsim table`'s columns as commands.md gives them: it left out cage_rest_angle_deg, which the
    table prints by default (tables.DEFAULT_COLUMNS, `table --help`)."""
    from bearingsim.tables import DEFAULT_COLUMNS

    text = " ".join((ROOT / "docs" / "commands.md").read_text().split())
    sentence = text[text.index("Columns: "):]
    sentence = sentence[:sentence.index("those present")]
    words = {"I_dec_mean_Ns": "`I_dec_mean`", "I_acc_mean_Ns": "`I_acc_mean`",
             "first_impact_speed_m_s": "first impact speed", "cage_slip": "cage slip",
             "cage_rest_angle_deg": "`cage_rest_angle` [deg]", "load_zone_half_angle_deg": "load-zone half angle",
             "wear_front_mean_m3_h": "`wear_front_mean`", "wear_rear_mean_m3_h": "`wear_rear_mean`"}
    assert set(words) == set(DEFAULT_COLUMNS)
    assert [k for k, w in words.items() if w not in sentence] == [], sentence
