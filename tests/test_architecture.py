"""The architecture as docs/architecture.md states it, checked against the code: no import cycle and no import of a
higher layer (function-level imports included), modules and functions of a readable size, and every file, Python
name and C symbol the document names exists, in the file it names."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "thermofriction"
DOC = ROOT / "docs" / "architecture.md"

#: modules allowed over MAX_MODULE_LINES, with why (parsers and tables)
LONG_MODULES = {}
MAX_MODULE_LINES = 400
#: functions allowed over MAX_FUNCTION_LINES, with why: parsers and tables, read top to bottom
LONG_FUNCTIONS = {
    "cli/parser.py:build_parser": "the command line's table of commands and options",
    "fmu_description.py:variables_of": "the table of the FMU's variables",
    "data/files.py:manifest_dataset": "the dataset file's parser",
    "data/matlab.py:read_experiment_mat": "a MATLAB experiment's parser",
}
MAX_FUNCTION_LINES = 80


def _modules():
    out = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


def _imports(name, path, modules):
    """The package modules ``name`` imports, anywhere in it (inside functions too). A module's own package
    (its __init__, which Python runs first) is not counted: importing a package's __init__ explicitly is."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join(up + ([node.module] if node.module else []))
            for alias in node.names:
                target = f"{base}.{alias.name}"
                if target in modules:
                    found.add(target)
                elif not (PACKAGE / f"{alias.name}.c").exists():  # (the compiled core is not a Python module)
                    found.add(base)
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
    return {t for t in found if t in modules and t != name}


def test_no_import_cycle_in_the_package_function_level_imports_included():
    modules = _modules()
    graph = {n: _imports(n, p, modules) for n, p in modules.items()}
    cycles, state = [], {}

    def visit(node, stack):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                cycles.append(stack[stack.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, stack)
        stack.pop()
        state[node] = "done"

    for n in sorted(graph):
        if n not in state:
            visit(n, [])
    assert not cycles, "\n".join(" -> ".join(c) for c in cycles)


def test_the_cycle_check_finds_a_cycle(tmp_path, monkeypatch):
    """The check itself: two modules importing each other inside functions are a cycle."""
    pkg = tmp_path / "thermofriction"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("def f():\n    from .b import g\n")
    (pkg / "b.py").write_text("def g():\n    from . import a\n")
    monkeypatch.setattr(__import__(__name__), "PACKAGE", pkg)
    modules = _modules()
    assert "thermofriction.b" in _imports("thermofriction.a", modules["thermofriction.a"], modules)
    assert "thermofriction.a" in _imports("thermofriction.b", modules["thermofriction.b"], modules)


def _docstring_lines(node) -> int:
    """The lines of ``node``'s own docstring (a module's, class's or function's): documentation, which the
    sizes below do not count (a numpydoc reference of a function's every argument is as long as it needs)."""
    body = getattr(node, "body", None)
    first = body[0] if body else None
    if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str):
        return first.end_lineno - first.lineno + 1
    return 0


def test_modules_and_functions_are_of_a_readable_size():
    """Lines of code: a module's and a function's lines less their docstrings' (the API reference's text)."""
    long_modules, long_functions = [], []
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE).as_posix()
        text = path.read_text(encoding="utf-8")
        tree = ast.parse(text)
        code = text.count("\n") - sum(_docstring_lines(n) for n in ast.walk(tree)
                                      if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef,
                                                        ast.AsyncFunctionDef)))
        if code > MAX_MODULE_LINES and rel not in LONG_MODULES:
            long_modules.append(f"{rel}: {code} lines of code")
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1 - _docstring_lines(node)
                if n > MAX_FUNCTION_LINES and f"{rel}:{node.name}" not in LONG_FUNCTIONS:
                    long_functions.append(f"{rel}:{node.name}: {n} lines of code")
    assert not long_modules and not long_functions, long_modules + long_functions


def _defined_names():
    names = set()
    for path in PACKAGE.rglob("*.py"):
        names.add(path.stem)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.add(node.name)
            elif isinstance(node, (ast.Assign, ast.AnnAssign)):
                for t in (node.targets if isinstance(node, ast.Assign) else [node.target]):
                    for n in ast.walk(t):
                        if isinstance(n, ast.Name):
                            names.add(n.id)
                        elif isinstance(n, ast.Attribute):
                            names.add(n.attr)
    return names


def _c_text():
    files = [p for p in (ROOT / "core").rglob("*") if p.suffix in (".c", ".h")] + [PACKAGE / "_core.c"]
    return "\n".join(p.read_text(encoding="utf-8", errors="replace") for p in files)


def _named_in(doc: str):
    """(paths, python names, C symbols) that ``doc`` names in backticks."""
    paths, python, c = set(), set(), set()
    tokens = []
    for token in re.findall(r"`([^`\n]+)`", doc):
        where = re.fullmatch(r"([\w./-]+\.(?:c|h|py)): ([\w, ]+)", token.strip())
        # "core/src/friction.c: lugre, dahl": the file, and the names in it
        tokens += [where.group(1)] + [f"{n.strip()}()" for n in where.group(2).split(",")] if where else [token]
    for token in tokens:
        token = token.strip()
        bare = re.sub(r"\(.*\)$", "", token)
        if re.fullmatch(r"(tf|TF)_\w+", bare):
            c.add(bare)
        elif re.fullmatch(r"[\w./-]+\.(py|c|h|md|toml|txt)|[\w.-]+(/[\w.-]*)+/?", token) and "*" not in token:
            paths.add(token)
        elif re.fullmatch(r"[A-Za-z_][\w]*(\.[A-Za-z_]\w*)*", bare) and (token.endswith(")") or "." in bare
                                                                         or bare[0].isupper() or "_" in bare):
            python.add(bare)
    return paths, python, c


def _exists(path: str) -> bool:
    roots = [ROOT, ROOT / "core", ROOT / "core" / "src", ROOT / "core" / "include" / "thermofriction",
             ROOT / "core" / "fmu", ROOT / "docs",
             ROOT / "tests", PACKAGE] + [d for d in PACKAGE.iterdir() if d.is_dir()]
    return any((r / path.rstrip("/")).exists() for r in roots)


#: words in backticks that are not names of the code (file keys, options, statuses, parameter symbols)
NOT_CODE = re.compile(r"^(x_e|x_p|m_e|T_0|T_em|C_th|R_th|P_ext|v_smooth|z_ba|sensor_offset|rtol_weight|max_steps|"
                      r"CI|SKBUILD|TF_SANITIZE|TF_BUILD_FMU|[A-Z][A-Z_]+_[A-Z]+)$")


def test_architecture_document_names_only_what_exists():
    doc = DOC.read_text(encoding="utf-8")
    paths, python, c = _named_in(doc)
    defined, c_text = _defined_names(), _c_text()
    # build products (the FMU binaries the package build installs under _fmu/) are not in the tree
    missing = [p for p in sorted(paths) if not _exists(p) and not p.startswith("_fmu/")]
    missing += [n for n in sorted(python) if not NOT_CODE.match(n) and n.split(".")[-1] not in defined
                and not re.search(rf"\b{n.split('.')[-1]}\b", c_text)]  # a C function or a binding's export
    missing += [s for s in sorted(c) if not NOT_CODE.match(s) and not re.search(rf"\b{s}\b", c_text)]
    assert not missing, missing
    assert len(paths) > 20 and len(python) > 20 and len(c) > 5  # the check reads what the document names


def test_the_document_check_catches_a_missing_name():
    paths, python, c = _named_in("the `identification/nowhere.py` module's `no_such_function()` and `tf_no_such`")
    assert paths == {"identification/nowhere.py"} and python == {"no_such_function"} and c == {"tf_no_such"}
    assert not _exists("identification/nowhere.py") and "no_such_function" not in _defined_names()


# -- layers: no module imports a module of a higher layer ----------------------------------------------------------

#: the heading of docs/architecture.md's table of the package's layers, lowest first, which the test reads
LAYERS_HEADING = "## Layers of the package"
#: imports from a lower layer to a higher one known today and being removed ("importer -> imported"); empty now
#: that the figures are low (issue 39). A module moved under a new layer (e.g. the fitting engine below the
#: measurements) may list here, commented, what its branch has not yet turned downward; the merge empties it.
KNOWN_UPWARD: set[str] = set()


def _layers(doc: str):
    """[(layer, [module or package names])] of the document's layer table, lowest first: a row's second cell names
    files (``results.py``, ``__init__.py``: the package's own) and folders (``models/``: a package and its
    modules)."""
    section = doc.split(LAYERS_HEADING, 1)[1].split("\n## ", 1)[0]
    rows = [r for r in section.splitlines() if r.startswith("|") and not set(r) <= set("|-: ")][1:]
    layers = []
    for row in rows:
        cells = [c.strip() for c in row.strip().strip("|").split("|")]
        names = []
        for token in re.findall(r"`([^`]+)`", cells[1]):
            path = token.strip().rstrip("/").removesuffix(".py")
            parts = [p for p in path.split("/") if p != "__init__"]
            names.append(".".join([PACKAGE.name] + parts))
        layers.append((cells[0], names))
    return layers


def _layer_of(module: str, layers) -> int | None:
    """The index of ``module``'s layer: the layer naming it or, failing that, its closest package."""
    best = None
    for i, (_, names) in enumerate(layers):
        for n in names:
            if (module == n or module.startswith(n + ".") and n != PACKAGE.name) and \
                    (best is None or len(n) > len(best[1])):
                best = (i, n)
    return best[0] if best else None


def _upward(graph, layers):
    """["importer -> imported"] where the imported module sits in a higher layer than the importer."""
    out = []
    for a in sorted(graph):
        for b in sorted(graph[a]):
            la, lb = _layer_of(a, layers), _layer_of(b, layers)
            if la is not None and lb is not None and lb > la:
                out.append(f"{a} -> {b} ({layers[la][0]} imports {layers[lb][0]})")
    return out


def test_every_module_has_a_layer_and_no_module_imports_a_higher_layer():
    """The layer table of docs/architecture.md (lowest first) against the import graph, imports inside functions
    included: every module of the package sits in one layer, and imports only its own layer and those below."""
    layers = _layers(DOC.read_text(encoding="utf-8"))
    modules = _modules()
    assert len(layers) >= 6, layers  # the check reads the table
    unplaced = [m for m in sorted(modules) if _layer_of(m, layers) is None]
    assert not unplaced, f"modules in no layer of {LAYERS_HEADING!r}: {unplaced}"
    graph = {n: _imports(n, p, modules) for n, p in modules.items()}
    upward = [u for u in _upward(graph, layers) if u.split(" (")[0] not in KNOWN_UPWARD]
    assert not upward, "\n".join(upward)
    stale = {k for k in KNOWN_UPWARD if not any(u.split(" (")[0] == k for u in _upward(graph, layers))}
    assert not stale, f"KNOWN_UPWARD lists imports that are gone: {sorted(stale)}"


def test_the_layer_check_finds_an_upward_import(tmp_path, monkeypatch):
    """The check itself: a low module importing a high one inside a function is an upward import; the package's
    own ``__init__.py`` is placed by its row, a folder's modules by the folder's."""
    pkg = tmp_path / "thermofriction"
    (pkg / "high").mkdir(parents=True)
    (pkg / "__init__.py").write_text("from . import low\n")
    (pkg / "low.py").write_text("def f():\n    from .high.page import g\n")
    (pkg / "high" / "__init__.py").write_text("")
    (pkg / "high" / "page.py").write_text("from ..low import f\n")
    monkeypatch.setattr(__import__(__name__), "PACKAGE", pkg)
    doc = (f"{LAYERS_HEADING}\n\n| layer | modules |\n|---|---|\n| low | `low.py` |\n| high | `high/` |\n"
           "| front | `__init__.py` |\n\n## Next\n")
    layers = _layers(doc)
    modules = _modules()
    graph = {n: _imports(n, p, modules) for n, p in modules.items()}
    assert [_layer_of(m, layers) for m in sorted(modules)] == [2, 1, 1, 0]  # the package, high, high.page, low
    assert _upward(graph, layers) == ["thermofriction.low -> thermofriction.high.page (low imports high)"]


# -- names in the files the document puts them in --------------------------------------------------------------------

def _python_definitions(path: Path):
    """({name defined anywhere in the file}, {class: {names defined in its body}}): functions, classes and
    assignment targets (attributes included) -- what the file defines, not what it imports."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names, classes = set(), {}
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            for t in (node.targets if isinstance(node, ast.Assign) else [node.target]):
                names.update(n.id if isinstance(n, ast.Name) else n.attr for n in ast.walk(t)
                             if isinstance(n, (ast.Name, ast.Attribute)))
        if isinstance(node, ast.ClassDef):
            classes[node.name] = {n.name for n in node.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))} | {
                n.target.id if isinstance(n, ast.AnnAssign) else t.id for n in node.body
                if isinstance(n, (ast.Assign, ast.AnnAssign))
                for t in (n.targets if isinstance(n, ast.Assign) else [n.target]) if isinstance(t, ast.Name)}
    return names, classes


def _c_defines(text: str, name: str) -> bool:
    """Whether C source ``text`` defines ``name``: a function with its body (a declaration or a call is not), a
    macro, an enum constant or a typedef."""
    n = re.escape(name)
    return bool(re.search(rf"^[A-Za-z_][\w \t*]*\b{n}\s*\([^;{{]*\)\s*\{{", text, re.M)
                or re.search(rf"^\s*#\s*define\s+{n}\b", text, re.M)
                or re.search(rf"^\s+{n}\s*(=[^=]|,|$)", text, re.M)
                or re.search(rf"\}}\s*{n}\s*;", text))


def _defined_in(path: Path, name: str) -> bool:
    """Whether the file (or, for a folder, one of its files) ``path`` defines ``name`` (``Class.attr``: the class,
    and the attribute in its body)."""
    files = sorted(path.rglob("*.py")) if path.is_dir() else [path]
    head, _, attr = name.rpartition(".")
    for f in files:
        if f.suffix in (".c", ".h"):
            if _c_defines(f.read_text(encoding="utf-8", errors="replace"), name):
                return True
            continue
        names, classes = _python_definitions(f)
        if (attr in classes.get(head.split(".")[-1], ())) if head and head[:1].isupper() else attr in names:
            return True
    return False


def _resolve(token: str, base: Path | None = None) -> Path | None:
    """The file or folder the document's ``token`` names: beside ``base`` (the folder a row speaks of) first, then
    from the roots the document's paths are written from."""
    roots = ([base] if base else []) + [PACKAGE, ROOT, ROOT / "core" / "src", ROOT / "core" / "include" / "thermofriction"]
    for r in roots:
        if (r / token.rstrip("/")).exists():
            return r / token.rstrip("/")
    return None


def _claims(doc: str):
    """[(where, the file or folders it names, name)]: every ``path: name, ...`` in backticks (the name in that
    file), and in a table row that names package files or folders, every other Python name of the row (in one of
    the files the row names). Dotted names whose head is a package module (``_bridge.run``) are that module's."""
    claims = []
    for line in doc.splitlines():
        tokens = re.findall(r"`([^`\n]+)`", line)
        files, base = [], None
        for token in tokens:
            where = re.fullmatch(r"([\w./-]+\.(?:c|h|py)): ([\w., ]+)", token.strip())
            if where:
                path = _resolve(where.group(1), base)
                claims += [(token, [path], n.strip()) for n in where.group(2).split(",")]
                continue
            if re.fullmatch(r"[\w./-]+\.py|[\w.-]+/", token.strip()):
                path = _resolve(token.strip(), base)
                if path is not None and PACKAGE in (path, *path.parents):
                    files.append(path)
                    base = path if path.is_dir() else path.parent
        _, python, _ = _named_in(" ".join(f"`{t}`" for t in tokens if not re.search(r"\.(c|h|py): ", t)))
        for n in sorted(python):
            head = n.split(".")[0]
            if head in ("thermofriction", "tf") or re.search(r"\.(xml|json|so|dll|toml|csv|html)$", n) or \
                    NOT_CODE.match(n) and not re.fullmatch(r"[A-Z][A-Z_]+_[A-Z]+", n):
                continue  # the package's own names (thermofriction.identify: a name it keeps), files, file keys
            module = _resolve(f"{head}.py") if "." in n and not head[:1].isupper() else None
            where = line.split("|")[1].strip() if line.startswith("|") else n
            if module is not None:  # control.friction_steps: in control.py
                claims.append((where, [module], n.split(".", 1)[1]))
            elif line.startswith("|") and files:  # a row of the package's files: in one of them
                claims.append((where, files, n))
            elif "." in n and head[:1].isupper():  # Model.parameters_at: in the class, wherever it is
                claims.append((where, [PACKAGE], n))
    return claims


def test_architecture_document_names_each_name_in_its_file():
    """Name in file, not name somewhere: ``core/src/thermal.c: tf_thermal_params`` holds only if thermal.c defines
    it, and a row of the module table that names ``models/laws.py`` and ``Law`` holds only if that file defines
    ``Law``."""
    claims = _claims(DOC.read_text(encoding="utf-8"))
    wrong = [f"{where}: {name} is not defined in {', '.join(str(f.relative_to(ROOT)) for f in files if f) or '?'}"
             for where, files, name in claims if not any(f is not None and _defined_in(f, name) for f in files)]
    assert not wrong, "\n".join(wrong)
    assert len(claims) > 40 and sum(f is not None and f.suffix == ".c" for _, fs, _ in claims for f in fs) > 10


def test_the_name_in_file_check_catches_a_name_in_another_file():
    """``core/src/thermal.c: tf_thermal_force`` (inline in thermal.h) and a row putting ``simulate`` in
    ``models/laws.py`` are caught; the true ones pass."""
    doc = ("`core/src/thermal.c: tf_thermal_force`, `thermal.h: tf_thermal_force`\n"
           "| `models/laws.py` | `Law`, `simulate()` |\n")
    claims = _claims(doc)
    verdicts = {(c[0].split("|")[0], c[2]): _defined_in(c[1][0], c[2]) for c in claims}
    assert verdicts == {("core/src/thermal.c: tf_thermal_force", "tf_thermal_force"): False,
                        ("thermal.h: tf_thermal_force", "tf_thermal_force"): True,
                        ("`models/laws.py`", "Law"): True, ("`models/laws.py`", "simulate"): False}
