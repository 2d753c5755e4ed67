//! The Python package's own tests (pytest, `python/tests`): the package is rebuilt from this
//! checkout into the virtual environment `target/python-venv` (which `.ci/run` makes, with
//! maturin, pytest, Pillow and Ray in it) and its tests compare it with this `texel` binary.
//! Without that environment the test prints why and passes, unless `CI=true`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The virtual environment's interpreter, when it has what the tests need.
fn venv_python() -> Option<PathBuf> {
    let python = root().join("target/python-venv/bin/python");
    let ready = python.exists()
        && Command::new(&python)
            .args(["-c", "import maturin, pytest, PIL, numpy"])
            .output()
            .is_ok_and(|o| o.status.success());
    if ready {
        return Some(python);
    }
    assert_ne!(
        std::env::var("CI").as_deref(),
        Ok("true"),
        "CI=true but target/python-venv lacks maturin, pytest, Pillow or numpy: .ci/run installs them"
    );
    eprintln!(
        "skipped: the Python package's tests need target/python-venv with maturin, pytest, Pillow and numpy (.ci/run makes it)"
    );
    None
}

/// `PATH` with the virtual environment's `bin` first.
fn with_venv_path(python: &Path) -> std::ffi::OsString {
    let bin = python
        .parent()
        .expect("the interpreter is in bin/")
        .to_path_buf();
    let rest = std::env::var_os("PATH").unwrap_or_default();
    std::env::join_paths(std::iter::once(bin).chain(std::env::split_paths(&rest)))
        .expect("PATH entries hold no separator")
}

#[test]
fn python_package_tests_pass() {
    let Some(python) = venv_python() else {
        return;
    };
    let build = Command::new(&python)
        .current_dir(root())
        .args([
            "-m",
            "pip",
            "install",
            "--quiet",
            "--no-deps",
            "--no-build-isolation",
            "./python",
        ])
        .env("PYO3_PYTHON", &python)
        // maturin's command sits beside the interpreter.
        .env("PATH", with_venv_path(&python))
        .env_remove("CARGO_TARGET_DIR")
        .output()
        .expect("pip runs");
    assert!(
        build.status.success(),
        "pip install ./python failed:\n{}",
        String::from_utf8_lossy(&build.stderr)
    );
    let tests = Command::new(&python)
        .current_dir(root())
        .args(["-m", "pytest", "-q", "python/tests"])
        .env("TEXEL_BIN", env!("CARGO_BIN_EXE_texel"))
        .output()
        .expect("pytest runs");
    let out = String::from_utf8_lossy(&tests.stdout);
    eprintln!("{out}");
    assert!(
        tests.status.success(),
        "the Python package's tests failed:\n{out}\n{}",
        String::from_utf8_lossy(&tests.stderr)
    );
}
