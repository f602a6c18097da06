"""The floors of the package, read from the source with ``ast`` (nothing is imported).

- The solver packages (``femadh/elastic/``, ``femadh/contact/``, ``femadh/laws/``), the
  discretisation (``femadh/discretisation/``) and the error machinery (``femadh/estimate/``)
  import neither the judges (``femadh.reference``: their independence is the point of a
  judge) nor the layers built on them (``femadh.runner``, ``femadh.studies``, which both use
  the discretisation and the error machinery: a home of its own, not one of theirs).
- Tests use public names only: no ``from femadh... import _name`` or
  ``from validation... import _name``, no private module in an import path.
"""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOLVERS = ("elastic", "contact", "laws", "discretisation", "estimate")
FORBIDDEN = ("femadh.reference", "femadh.runner", "femadh.studies")


def _absolute(module, level, path, root):
    """The dotted module an import in ``path`` names (relative imports resolved)."""
    if not level:
        return module or ""
    pkg = list(path.relative_to(root).with_suffix("").parts)[:-level]
    return ".".join(pkg + ([module] if module else []))


def imports(path, root=ROOT):
    """Every (line, dotted module, imported names) of one source file, wherever the import
    sits (module level or inside a function)."""
    out = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name, ()) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            mod = _absolute(node.module, node.level, path, root)
            out.append((node.lineno, mod, tuple(a.name for a in node.names)))
            # "from femadh import reference" names the judge as well
            out += [(node.lineno, f"{mod}.{a.name}", ()) for a in node.names]
    return out


def floor_violations(root=ROOT):
    bad = []
    for pkg in SOLVERS:
        for path in sorted((root / "femadh" / pkg).rglob("*.py")):
            for line, mod, _ in imports(path, root):
                if any(mod == f or mod.startswith(f + ".") for f in FORBIDDEN):
                    bad.append(f"{path.relative_to(root)}:{line} imports {mod}")
    return bad


def private_imports(root=ROOT):
    bad = []
    for path in sorted((root / "tests").glob("*.py")):
        for line, mod, names in imports(path, root):
            if mod.split(".")[0] not in ("femadh", "validation"):
                continue
            parts = [p for p in mod.split(".") if not p.startswith("__")]
            private = [n for n in names if n.startswith("_")]
            private += [p for p in parts if p.startswith("_")]
            if private:
                bad.append(f"{path.relative_to(root)}:{line} imports {mod}: {private}")
    return bad


def test_solver_packages_import_no_judge_runner_or_study():
    assert floor_violations() == []


def test_tests_import_no_private_name():
    assert private_imports() == []


@pytest.mark.parametrize("source, caught", [
    ("from ..reference.layered import LayeredHalfSpace\n", True),
    ("def f():\n    from femadh.runner import estimates\n", True),
    ("from femadh import studies\n", True),
    ("import femadh.reference.hertz\n", True),
    ("from .green import GreenOperator\nfrom ..materials import IsotropicMaterial\n", False),
])
def test_the_floor_rule_catches_an_upward_import(tmp_path, source, caught):
    """The rule on a planted file (relative, absolute, inside a function, a package named in
    the import list) - and an ordinary sideways import left alone."""
    pkg = tmp_path / "femadh" / "elastic"
    pkg.mkdir(parents=True)
    (pkg / "planted.py").write_text(source)
    assert bool(floor_violations(tmp_path)) is caught


@pytest.mark.parametrize("source, caught", [
    ("from femadh.studies.regime import _solve\n", True),
    ("def test():\n    from validation.roughness import _slider\n", True),
    ("from femadh._threads import limit\n", True),
    ("from femadh.studies.regime import solve_point\nfrom scipy import _lib\n", False),
])
def test_the_private_rule_catches_a_private_import(tmp_path, source, caught):
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "test_planted.py").write_text(source)
    assert bool(private_imports(tmp_path)) is caught
