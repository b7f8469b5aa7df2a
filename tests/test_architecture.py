"""The package and the crates keep the shape docs/architecture.md describes (measured by
tests/structure.py and tests/rust_structure.py)."""

from __future__ import annotations

from pathlib import Path

import rust_structure
from structure import measure

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "python" / "dnnevo"
CRATES = sorted(p.parent for p in (ROOT / "crates").glob("*/Cargo.toml"))


def test_no_import_loop_and_no_task_name_outside_the_tasks() -> None:
    shape = measure(PACKAGE)
    assert shape.loops == []
    assert shape.task_name_branches == [], "a layer above the tasks branches on a task's name"


def test_at_most_five_deferred_imports() -> None:
    # pyplot, tqdm, Dask and Pillow: each one costs start-up time or is an optional extra, and
    # says so where it is imported.
    deferred = measure(PACKAGE).deferred
    assert len(deferred) <= 5, "\n".join(deferred)


def test_the_measure_sees_a_loop_and_a_deferred_import(tmp_path: Path) -> None:
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from pkg import b\n")
    (pkg / "b.py").write_text("def f():\n    from pkg import a\n    return a\n")
    (pkg / "c.py").write_text("def g(config):\n    return config.task == 'nav1d'\n")
    shape = measure(pkg)
    assert shape.loops and len(shape.deferred) == 1 and len(shape.task_name_branches) == 1


def test_no_module_loop_in_any_crate() -> None:
    assert len(CRATES) == 5
    for crate in CRATES:
        assert rust_structure.loops(crate) == [], crate.name


def test_the_rust_measure_sees_a_loop_through_a_group_and_not_through_a_comment(tmp_path: Path) -> None:
    src = tmp_path / "src"
    (src / "b").mkdir(parents=True)
    (src / "a.rs").write_text("use crate::{c, b::{x, y}};\n")
    (src / "b" / "mod.rs").write_text("/// See [`crate::c`].\nmod inner;\n")
    (src / "b" / "inner.rs").write_text("fn f() { crate::a::g() }\n")
    (src / "c.rs").write_text("// crate::a\n")
    assert rust_structure.arrows(tmp_path) == {("a", "c"), ("a", "b"), ("b", "a")}
    assert rust_structure.loops(tmp_path) == [["a", "b", "a"]]


def test_the_rust_measure_follows_the_root_s_re_exports_and_super_to_the_root(tmp_path: Path) -> None:
    src = tmp_path / "src"
    (src / "b").mkdir(parents=True)
    (src / "lib.rs").write_text("mod a;\nmod b;\nmod c;\npub use b::{inner::X, Y as Z};\npub use c::W;\n")
    (src / "a.rs").write_text("use crate::X;\nfn f() -> crate::Z { todo!() }\n")
    (src / "b" / "mod.rs").write_text("pub mod inner;\npub struct Y;\n")
    (src / "b" / "inner.rs").write_text("pub struct X;\nfn g() { super::super::c::h(); super::Y; }\n")
    (src / "c.rs").write_text("pub struct W;\npub fn h() {}\n")
    assert rust_structure.arrows(tmp_path) == {("a", "b"), ("b", "c")}
    (src / "c.rs").write_text("pub struct W;\npub fn h() { let _ = crate::X; }\n")
    assert rust_structure.loops(tmp_path) == [["b", "c", "b"]]
