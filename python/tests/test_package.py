"""The package as users get it: installed from the wheel, typed, documented, with an
example that runs."""

from __future__ import annotations

import ast
import doctest
import inspect
import subprocess
import sys
from pathlib import Path

import hstl
from conftest import REPO

PACKAGE = Path(hstl.__file__).parent


def test_the_tests_run_the_installed_package():
    assert "site-packages" in hstl.__file__, hstl.__file__
    assert (PACKAGE / "py.typed").is_file() and (PACKAGE / "_hstl.pyi").is_file()
    assert hstl.__version__ == "0.1.0"


def stub_classes():
    tree = ast.parse((PACKAGE / "_hstl.pyi").read_text())
    return {node.name: node for node in tree.body if isinstance(node, ast.ClassDef)}


def test_the_stubs_name_what_the_module_has_with_the_same_parameters():
    classes = stub_classes()
    exported = {"Diagnostic", "Spec", "OnlineMonitor", "World", "ContinuousWorld", "Policy"}
    assert set(classes) == exported | {"Generator", "EpisodeMonitor", "EpisodeBatch", "_StudyOut"}
    for name, node in classes.items():
        runtime = getattr(hstl if name in exported else hstl._hstl, name)
        stubbed = set()
        for item in node.body:
            if isinstance(item, ast.FunctionDef):
                if item.name.startswith("_"):
                    continue
                stubbed.add(item.name)
                attr = getattr(runtime, item.name)
                if any(isinstance(d, ast.Name) and d.id == "property" for d in item.decorator_list):
                    assert inspect.isdatadescriptor(attr), f"{name}.{item.name} is not a property"
                    continue
                params = [a.arg for a in item.args.args + item.args.kwonlyargs]
                if params and params[0] == "self":
                    params = params[1:]
                got = list(inspect.signature(attr).parameters)
                if got and got[0] == "self":
                    got = got[1:]
                assert got == params, f"{name}.{item.name}: runtime {got}, stub {params}"
            elif isinstance(item, ast.AnnAssign):
                stubbed.add(item.target.id)
        public = {a for a in dir(runtime) if not a.startswith("_")}
        assert public == stubbed, f"{name}: runtime {sorted(public)}, stubs {sorted(stubbed)}"


def test_help_reads_well():
    text = inspect.getdoc(hstl.Spec)
    assert "Spec.load(path)" in text and "pickles" in text
    for method in ["load", "parse", "robustness", "signal", "signal_batch", "online", "horizon"]:
        doc = inspect.getdoc(getattr(hstl.Spec, method))
        assert doc and len(doc) > 40, method
    signature = str(inspect.signature(hstl.Spec.signal_batch))
    assert signature == (
        "(self, /, traces, formula=None, *, columns=None, threads=None, windows='clipped', "
        "max_gap=None, relative=False)"
    )
    assert "final" in inspect.getdoc(hstl.OnlineMonitor)


def test_the_package_docstring_example_runs():
    failures, tried = doctest.testmod(hstl, verbose=False)
    assert tried > 0 and failures == 0


def test_the_example_script_runs():
    script = REPO / "examples" / "python" / "monitor.py"
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "robustness at step 0" in out.stdout


def test_the_build_backend_stops_with_one_line_without_cargo(tmp_path):
    # `pip install ./python` on a machine without Rust: the backend's first hook that needs
    # cargo, run as pip runs it (in python/, with this interpreter), with no cargo on PATH.
    code = (
        "import sys; sys.path.insert(0, 'build_backend'); import hstl_build; "
        f"hstl_build.prepare_metadata_for_build_wheel({str(tmp_path)!r})"
    )
    env = {"PATH": str(tmp_path), "HOME": str(tmp_path)}
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO / "python", env=env, capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 1 and out.stdout == "", out
    lines = out.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("hstl: cannot build: cargo is not on PATH"), out.stderr
    assert "rustup.rs" in lines[0] and "scripts/wheel" in lines[0]
    # And maturin's toolchain download is off unless asked for.
    code = "import sys; sys.path.insert(0, 'build_backend'); import hstl_build; print(hstl_build.get_requires_for_build_wheel())"
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO / "python", env=env, capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 0 and "puccinialin" not in out.stdout, out
