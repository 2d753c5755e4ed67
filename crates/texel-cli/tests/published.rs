//! What publishing an output may never do: follow another user's link planted in a sticky
//! directory, replace or delete a file the run reads or a file texel did not write, widen a private
//! directory's mode, write one output over another however the two are spelled, or find an output
//! unwritable or an input mismatched only after the work.

use std::process::{Command, Stdio};

use crate::util::*;

/// A scene of [`HEAD`]'s camera over [`QUAD`] whose texture `t` is the PNG at `texture`.
fn scene_with_texture(texture: &std::path::Path) -> String {
    let head = HEAD.replace(
        "procedural = \"checker\"\nsize = 64\nchecks = 4\n",
        &format!("path = {:?}\n", texture.to_string_lossy()),
    );
    format!("{head}{QUAD}")
}

#[test]
fn compare_never_replaces_a_file_its_scene_reads() {
    let d = Dir::new("published-texture");
    // `M` holds `texel mips` output; the scene's texture is one of its levels.
    let m = d.join("M");
    ok(&["mips", &ground_png(&d), "--out", m.to_str().unwrap()]);
    let level = m.join("level-00-64x64.png");
    let before = file_bytes(&level);
    let scene = d.write("scene.toml", scene_with_texture(&level));
    let err = fails(
        &small_compare(&[scene.to_str().unwrap()], m.to_str().unwrap()),
        1,
        &["holds the input", "level-00-64x64.png"],
    );
    assert!(!err.contains("reference:"), "the comparison ran: {err}");
    assert_eq!(file_bytes(&level), before, "the texture changed");
}

/// `texel compare` at 16 x 12 with one sample and the nearest filter into `out`, `args` (a scene,
/// `--extra`) before `--out`.
fn small_compare(args: &[&str], out: &str) -> Vec<String> {
    let mut all = vec!["compare".to_string()];
    all.extend(args.iter().map(|a| a.to_string()));
    for a in [
        "--size",
        "16x12",
        "--spp",
        "1",
        "--filters",
        "nearest",
        "--out",
        out,
    ] {
        all.push(a.to_string());
    }
    all
}

/// A 64 x 64 PNG written by `texel render`, for inputs.
fn ground_png(d: &Dir) -> String {
    let p = d.arg("ground.png");
    ok(&["render", "--size", "64x64", "-o", &p]);
    p
}

#[test]
fn an_empty_marker_owns_nothing() {
    let d = Dir::new("published-touch");
    let thesis = d.join("thesis");
    std::fs::create_dir(&thesis).unwrap();
    d.write("thesis/thesis.tex", "chapter 1");
    d.write("thesis/.texel-output", "");
    fails(
        &small_compare(&[], thesis.to_str().unwrap()),
        1,
        &["did not write"],
    );
    assert_eq!(file_bytes(thesis.join("thesis.tex")), b"chapter 1");
}

#[cfg(unix)]
#[test]
fn a_private_output_directory_stays_private() {
    use std::os::unix::fs::PermissionsExt;
    let d = Dir::new("published-mode");
    let private = d.join("priv");
    std::fs::create_dir(&private).unwrap();
    std::fs::set_permissions(&private, std::fs::Permissions::from_mode(0o700)).unwrap();
    ok(&small_compare(&[], private.to_str().unwrap()));
    assert!(private.join("index.html").is_file());
    let mode = std::fs::metadata(&private).unwrap().permissions().mode() & 0o7777;
    assert_eq!(mode, 0o700, "{mode:o}");
}

/// A planted link in a sticky, world-writable directory, owned by another user, is not followed
/// (needs root, to give the link another owner).
#[cfg(unix)]
#[test]
fn a_planted_link_is_not_followed() {
    use std::os::unix::fs::PermissionsExt;
    if !is_root() {
        eprintln!("skipped: needs root to give a link another owner");
        return;
    }
    let d = Dir::new("published-planted");
    let sticky = d.join("tmp");
    std::fs::create_dir(&sticky).unwrap();
    std::fs::set_permissions(&sticky, std::fs::Permissions::from_mode(0o1777)).unwrap();
    let victim = d.write("some.conf", "root's settings\n");
    let link = sticky.join("out.png");
    std::os::unix::fs::symlink(&victim, &link).unwrap();
    std::os::unix::fs::lchown(&link, Some(4242), Some(4242)).unwrap();
    fails(
        &["render", "--size", "16x9", "-o", link.to_str().unwrap()],
        1,
        &["protected_symlinks"],
    );
    assert_eq!(file_bytes(&victim), b"root's settings\n");
    assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// `texel reference` with `args`, standard output into a file of `d`; returns (status, stderr,
/// what reached standard output).
fn reference_into_stdout(d: &Dir, args: &[&str]) -> (Option<i32>, String, Vec<u8>) {
    let log = d.join("stdout.bin");
    let out = Command::new(env!("CARGO_BIN_EXE_texel"))
        .args(["reference", "--size", "16x9", "--spp", "1"])
        .args(args)
        .stdout(std::fs::File::create(&log).unwrap())
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    (out.status.code(), stderr(&out), file_bytes(&log))
}

#[test]
fn one_output_named_twice_is_refused_before_any_work() {
    let d = Dir::new("published-aliases");
    for (o, map) in [
        ("-", "/dev/stdout"),
        ("/dev/stdout", "/dev/fd/1"),
        ("-", "-"),
        ("/proc/self/fd/1", "/dev/stdout"),
    ] {
        let (code, err, bytes) = reference_into_stdout(&d, &["-o", o, "--error-map", map]);
        assert_eq!(code, Some(1), "-o {o} --error-map {map}: {err}");
        assert!(err.contains("same file or stream"), "{err}");
        assert!(
            bytes.is_empty(),
            "-o {o} --error-map {map} wrote {} bytes",
            bytes.len()
        );
    }
    // A dangling link to the -o name, and another spelling of one path.
    let link = d.join("l.png");
    std::os::unix::fs::symlink("out.png", &link).unwrap();
    let out = d.arg("out.png");
    for map in [link.to_str().unwrap(), &format!("{}/./out.png", d.arg("."))] {
        fails(
            &[
                "reference",
                "--size",
                "16x9",
                "--spp",
                "1",
                "-o",
                &out,
                "--error-map",
                map,
            ],
            1,
            &["same file or stream"],
        );
        assert!(!d.join("out.png").exists());
    }
    // Standard output redirected to a file, and the same file by name.
    let target = d.join("stdout.bin");
    let (code, err, _) =
        reference_into_stdout(&d, &["-o", "-", "--error-map", target.to_str().unwrap()]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("same file or stream"), "{err}");
    // Two outputs of their own are fine.
    ok(&[
        "reference",
        "--size",
        "16x9",
        "--spp",
        "1",
        "-o",
        &out,
        "--error-map",
        &d.arg("err.png"),
    ]);
}

#[test]
fn outputs_and_inputs_are_checked_before_the_first_pixel() {
    let d = Dir::new("published-early");
    // An error map in a missing directory: refused before -o is replaced.
    let out = d.write("out.png", "the old image");
    let err = fails(
        &[
            "reference",
            "--size",
            "16x9",
            "--spp",
            "1",
            "-o",
            out.to_str().unwrap(),
            "--error-map",
            &d.arg("missing/err.png"),
        ],
        1,
        &["missing/err.png"],
    );
    assert!(!err.contains("reference:"), "the reference ran: {err}");
    assert_eq!(file_bytes(&out), b"the old image");
    // The same for render's -o in a missing directory, before the scene is rendered.
    fails(
        &["render", "--size", "16x9", "-o", &d.arg("missing/r.png")],
        1,
        &["missing/r.png"],
    );
    // An --extra image of another size: refused as an input, not as a report that cannot be
    // written.
    let small = d.arg("small.png");
    ok(&["render", "--size", "10x10", "-o", &small]);
    let err = fails(
        &[
            "compare",
            "--size",
            "32x18",
            "--spp",
            "1",
            "--filters",
            "nearest",
            "--extra",
            &format!("peer={small}"),
            "--out",
            &d.arg("report"),
        ],
        1,
        &["10x10", "32x18"],
    );
    assert!(!err.contains("cannot write the report"), "{err}");
    assert!(!d.join("report").exists());
    // A frame too narrow for SSIM's window is a usage error up front.
    fails(
        &[
            "compare",
            "--size",
            "10x720",
            "--spp",
            "1",
            "--filters",
            "nearest",
            "--out",
            &d.arg("narrow"),
        ],
        1,
        &["10x720", "11"],
    );
    assert!(!d.join("narrow").exists());
}

/// A link another user planted in a sticky directory is not followed as a directory of the path
/// either, and another user's directory planted there does not receive a report (needs root).
#[cfg(unix)]
#[test]
fn planted_directories_and_directory_links_are_refused() {
    use std::os::unix::fs::PermissionsExt;
    if !is_root() {
        eprintln!("skipped: needs root to give a link another owner");
        return;
    }
    let d = Dir::new("published-planted-dir");
    let sticky = d.join("tmp");
    std::fs::create_dir(&sticky).unwrap();
    std::fs::set_permissions(&sticky, std::fs::Permissions::from_mode(0o1777)).unwrap();
    let victim = d.join("victim");
    std::fs::create_dir(&victim).unwrap();
    let link = sticky.join("linkdir");
    std::os::unix::fs::symlink(&victim, &link).unwrap();
    std::os::unix::fs::lchown(&link, Some(4242), Some(4242)).unwrap();
    fails(
        &[
            "render",
            "--size",
            "16x9",
            "-o",
            link.join("x.png").to_str().unwrap(),
        ],
        1,
        &["protected_symlinks"],
    );
    assert!(std::fs::read_dir(&victim).unwrap().next().is_none());
    let planted = sticky.join("report");
    std::fs::create_dir(&planted).unwrap();
    std::os::unix::fs::chown(&planted, Some(4242), Some(4242)).unwrap();
    fails(
        &small_compare(&[], planted.to_str().unwrap()),
        1,
        &["another user's directory"],
    );
    assert!(std::fs::read_dir(&planted).unwrap().next().is_none());
}

#[test]
fn report_names_reach_no_terminal_raw() {
    let d = Dir::new("published-labels");
    let img = d.arg("e.png");
    ok(&["render", "--size", "16x12", "-o", &img]);
    let err = fails(
        &small_compare(
            &["--extra", &format!("x\u{1b}[2J\u{202e}={img}")],
            &d.arg("report"),
        ),
        1,
        &["control or bidirectional", "\\u{1b}"],
    );
    assert!(
        !err.contains('\u{1b}') && !err.contains('\u{202e}'),
        "{err}"
    );
}

#[test]
fn a_scene_compare_cannot_score_is_refused_before_the_reference() {
    let d = Dir::new("published-coverage");
    // Looking away from the quad: nothing covered.
    let away = d.write(
        "away.toml",
        format!(
            "{}{QUAD}",
            HEAD.replace("target = [0.0, 0.0, 0.0]", "target = [0.0, 0.0, 6.0]")
        ),
    );
    // The quad seen only in a corner strip, closer to the edge than SSIM's window reaches.
    let corner = d.write(
        "corner.toml",
        format!(
            "{}\n[[meshes]]\ntexture = \"t\"\npositions = [[-10.0, -10.0, 0.0], [10.0, -10.0, 0.0], \
             [10.0, -1.2, 0.0], [-10.0, -1.2, 0.0]]\nuvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], \
             [0.0, 0.0]]\ntriangles = [[0, 1, 2], [0, 2, 3]]\n",
            HEAD
        ),
    );
    for (scene, needle) in [
        (&away, "covers no pixel centre"),
        (&corner, "from the frame's edge"),
    ] {
        let err = fails(
            &[
                "compare",
                scene.to_str().unwrap(),
                "--spp",
                "4096",
                "--filters",
                "nearest",
                "--out",
                &d.arg("report"),
            ],
            1,
            &[needle],
        );
        // Refused before the 4096-sample reference ran (it would print its summary).
        assert!(!err.contains("reference:"), "{err}");
        assert!(!d.join("report").exists());
    }
}
