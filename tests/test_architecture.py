"""The architecture as docs/architecture.md states it, checked against the code: no import cycle (function-level
imports included), modules and functions of a readable size, and every file, Python name and C symbol the
document names exists."""

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
