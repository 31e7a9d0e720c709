"""How the kit's Python fits together (DESIGN.md section 1): labkit/, grading/, tools/ and tests/
import each other as packages from the repository root, never by editing sys.path or loading a
file by path; the grader imports nothing from tools/, labkit/ nothing from either; the grader's
modules import down its floors (GRADER_FLOORS) and at most MAX_GRADER_TOP of them sit at its
top; every command under tools/ is reached from a make target that `make help` lists; every
Python or shell path and every `python3 -m` module the repository names exists. Reads files
only: well under a second; `make lint` runs it."""
import ast
import fnmatch
import importlib.util
import re
import subprocess

from labkit.harness import ROOT

MAKEFILES = ["Makefile", "cuda.mk", "grading/grading.mk",
             *sorted(str(p.relative_to(ROOT)) for p in ROOT.glob("labs/*/lab.mk"))]
TEXT_SUFFIXES = {".md", ".py", ".sh", ".mk", ".h", ".cpp", ".cu", ".cuh", ".json", ".txt", ""}
MODULE = re.compile(r"-m ((?:labkit|grading|tools)(?:\.[a-z_][a-z0-9_]*)*)\b")
PATH = re.compile(r"(?<![\w/.-])((?:labkit|grading|tools)/[\w/.-]*\w\.(?:py|sh))\b")


def tracked(*patterns: str) -> list:
    out = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z", *patterns],
                         capture_output=True, check=True).stdout.decode()
    return [ROOT / f for f in out.split("\0") if f and (ROOT / f).is_file()]


def trees(files):
    for f in files:
        yield f, ast.parse(f.read_text(), str(f))


def names(node) -> str:
    """a.b.c of an attribute chain, '' for anything else."""
    if isinstance(node, ast.Attribute):
        return f"{names(node.value)}.{node.attr}" if names(node.value) else ""
    return node.id if isinstance(node, ast.Name) else ""


def test_no_sys_path_edits_and_no_loading_by_file_path():
    found = []
    for f, tree in trees(tracked("*.py")):
        for node in ast.walk(tree):
            called = names(node.func) if isinstance(node, ast.Call) else ""
            if called.startswith("sys.path.") or called.endswith(
                    ("spec_from_file_location", "SourceFileLoader", "run_path")):
                found.append(f"{f.relative_to(ROOT)}:{node.lineno}: {called}")
            if isinstance(node, ast.Assign) and any(names(t) == "sys.path" for t in node.targets):
                found.append(f"{f.relative_to(ROOT)}:{node.lineno}: sys.path = ...")
    assert not found, found


def imports_of(patterns, packages) -> list:
    """Every import, in the files `patterns` match, of a module of one of `packages`."""
    found = []
    for f, tree in trees(tracked(*patterns)):
        for node in ast.walk(tree):
            modules = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                       [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            found += [f"{f.relative_to(ROOT)}:{node.lineno}: {m}" for m in modules
                      if any(m == p or m.startswith(p + ".") for p in packages)]
    return found


def test_the_grader_imports_nothing_from_tools():
    found = imports_of(("grading/*.py", "grading/**/*.py"), ("tools",))
    assert not found, found


def test_the_library_imports_neither_the_grader_nor_the_tools():
    """labkit/ is below both: the grader and the tools import it, never the other way."""
    found = imports_of(("labkit/*.py", "labkit/**/*.py"), ("grading", "tools"))
    assert not found, found


def tool_commands() -> dict:
    """Each command under tools/: its `python3 -m` module (a module with a __main__ guard, a
    package with __main__.py) or its shell script's path."""
    commands = {}
    for f in tracked("tools/*.py", "tools/**/*.py"):
        rel = f.relative_to(ROOT).with_suffix("")
        if f.name == "__main__.py":
            commands[".".join(rel.parent.parts)] = f
        elif 'if __name__ == "__main__"' in f.read_text():
            commands[".".join(rel.parts)] = f
    for f in tracked("tools/*.sh", "tools/**/*.sh"):
        commands[str(f.relative_to(ROOT))] = f
    return commands


def recipes() -> dict:
    """Each make target's recipe, as written in the Makefiles."""
    rules, target = {}, None
    for name in MAKEFILES:
        for line in (ROOT / name).read_text().splitlines():
            rule = re.match(r"^([\w.-]+(?: [\w.-]+)*):(?!=)", line)
            if rule:
                target = rule.group(1).split()[0]
            elif line.startswith("\t") and target:
                rules[target] = rules.get(target, "") + line + "\n"
            elif line and not line.startswith(("#", " ")):
                target = None
    return rules


def test_every_tool_is_reached_from_a_make_target_make_help_lists():
    rules = recipes()
    help_text = subprocess.run(["make", "-s", "-C", str(ROOT), "help"], capture_output=True,
                               text=True, check=True).stdout

    def invoked(command: str, text: str) -> bool:
        module = command.replace(".", r"\.")
        return bool(re.search(rf"-m {module}(?![\w.])" if "/" not in command else
                              rf"(?<![\w/]){re.escape(command)}\b", text))

    commands = tool_commands()
    reached = {c: t for c in commands for t, recipe in rules.items() if invoked(c, recipe)}
    # A command run by a script a make target runs (tools/gpu/check.sh runs tools.gpu.report).
    for command in set(commands) - set(reached):
        for script, target in list(reached.items()):
            if script.endswith(".sh") and invoked(command, (ROOT / script).read_text()):
                reached[command] = target
    # A module that its package's __main__ runs (tools.tradeoff.run).
    for command in set(commands) - set(reached):
        package = command.rpartition(".")[0]
        main = ROOT / package.replace(".", "/") / "__main__.py"
        if package in reached and main.is_file() and f"from {command} import" in main.read_text():
            reached[command] = reached[package]
    assert set(reached) == set(commands), sorted(set(commands) - set(reached))
    unlisted = {c: t for c, t in reached.items() if f"make {t}" not in help_text}
    assert not unlisted, unlisted


def test_paths_and_modules_the_repository_names_exist():
    missing = []
    for f in tracked():
        if f.suffix not in TEXT_SUFFIXES or f.stat().st_size > 1 << 20:
            continue
        text = f.read_text(errors="replace")
        for m in PATH.finditer(text):
            if not (ROOT / m.group(1)).is_file():
                missing.append(f"{f.relative_to(ROOT)}: {m.group(1)}")
        for m in MODULE.finditer(text):
            if importlib.util.find_spec(m.group(1)) is None:
                missing.append(f"{f.relative_to(ROOT)}: -m {m.group(1)}")
    assert not missing, missing


def module_of(path) -> str:
    """grading/checks/speed.py -> grading.checks.speed; a package's __init__.py -> its name."""
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def module_graph(package: str) -> dict[str, set[str]]:
    """Module -> the modules of `package` (its subpackages' included) it imports, at its top or
    inside a function, by dotted name: `from grading.checks import speed` is grading.checks.speed,
    `from grading.checks.speed import x` too."""
    files = tracked(f"{package}/*.py", f"{package}/**/*.py")
    modules = {module_of(f) for f in files}
    graph = {}
    for f, tree in trees(files):
        deps = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == package:
                deps |= {f"{node.module}.{a.name}" if f"{node.module}.{a.name}" in modules
                         else node.module for a in node.names}
            elif isinstance(node, ast.Import):
                deps |= {a.name for a in node.names if a.name.split(".")[0] == package}
        graph[module_of(f)] = deps - {module_of(f), package}
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Each import cycle once, as the modules along it."""
    found, done = [], set()

    def visit(node, path):
        for nxt in sorted(graph.get(node, ())):
            if nxt in path:
                cycle = path[path.index(nxt):]
                if frozenset(cycle) not in done:
                    done.add(frozenset(cycle))
                    found.append(cycle + [nxt])
            elif nxt in graph:
                visit(nxt, path + [nxt])
    for start in sorted(graph):
        visit(start, [start])
    return found


def test_the_graders_modules_import_in_one_direction():
    """No module of grading/ imports one that imports it back, even inside a function: each
    has one job, and a check's module needs nothing from the grade that runs it."""
    assert cycles(module_graph("grading")) == []
    assert cycles({"checks": {"hidden"}, "hidden": {"checks"}}) == [["checks", "hidden", "checks"]]


# The grader's floors, lowest first. A module imports modules of its own floor or a lower one,
# never a higher one, and never a floor beside its own: the classes (batch, Slurm, the class's
# page) and the releases (student repositories, hand-ins, Gradescope) both stand on the grade
# and know nothing of each other. The grader's top holds the grade and the modules every floor
# shares; a module at the top not named in a higher floor is a shared one (floor 0).
GRADER_FLOORS = [
    ("shared", 0, ("grading.*",)),  # shown, results, compile, students_tree, references...
    ("checks", 1, ("grading.checks", "grading.checks.*")),
    ("grade", 2, ("grading.grade",)),  # the rubrics and their order: the one grade-level module
    ("classes", 3, ("grading.classes", "grading.classes.*")),
    ("releases", 3, ("grading.releases", "grading.releases.*")),
]
MAX_GRADER_TOP = 14  # .py files directly in grading/, __init__.py included


def floor_of(module: str) -> tuple[str, int]:
    """The last floor whose patterns match `module` (grading.grade matches "grading.*" too)."""
    found = [(name, level) for name, level, patterns in GRADER_FLOORS
             if any(fnmatch.fnmatchcase(module, p) for p in patterns)]
    return found[-1]


def test_the_graders_modules_import_down_its_floors():
    """The checks never import the grade, a class's or a release's modules; the shared modules
    at the top import no subpackage; classes and releases never import each other."""
    upward = []
    for module, deps in module_graph("grading").items():
        if module == "grading":
            continue
        name, level = floor_of(module)
        for dep in deps:
            dep_name, dep_level = floor_of(dep)
            if dep_level > level or (dep_level == level and dep_name != name):
                upward.append(f"{module} ({name}) imports {dep} ({dep_name})")
    assert not upward, upward
    assert floor_of("grading.shown") == ("shared", 0)
    assert floor_of("grading.grade") == ("grade", 2)
    assert floor_of("grading.checks.speed") == ("checks", 1)


def test_the_graders_top_holds_at_most_a_few_modules():
    """What is not the grade or shared by its floors lives in a subpackage by concern."""
    top = sorted(f.name for f in tracked("grading/*.py") if f.parent == ROOT / "grading")
    assert len(top) <= MAX_GRADER_TOP, top
