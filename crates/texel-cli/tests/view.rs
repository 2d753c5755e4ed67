//! `texel view` in a real X server: each test starts its own Xvfb (`-displayfd` picks a free
//! display, so tests run in parallel) and runs the viewer scripted (`--keys`, `--frames`,
//! `--screenshot`). Without Xvfb the tests print why and pass, unless `CI=true`, where a missing
//! X server fails them (`.ci/run` installs Debian's `xvfb`).

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};

use texel::quality::{psnr, Image8};

use crate::util::*;

/// A running Xvfb, killed on drop.
pub(crate) struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    /// Start Xvfb, or `None` (with the reason printed) where it is not installed and CI does not
    /// demand it.
    pub(crate) fn start() -> Option<Xvfb> {
        let spawned = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "1600x1200x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn();
        let mut child = match spawned {
            Ok(c) => c,
            Err(e) => {
                assert_ne!(
                    std::env::var("CI").as_deref(),
                    Ok("true"),
                    "CI=true but no X server to test texel view in ({e}): apt-get install xvfb"
                );
                eprintln!("skipped: cannot start Xvfb ({e}); apt-get install xvfb");
                return None;
            }
        };
        let mut line = String::new();
        BufReader::new(child.stdout.take().expect("piped"))
            .read_line(&mut line)
            .expect("Xvfb's display number");
        let n: u32 = line.trim().parse().expect("Xvfb prints its display number");
        Some(Xvfb {
            child,
            display: format!(":{n}"),
        })
    }

    /// The display's name, for `DISPLAY`.
    pub(crate) fn display(&self) -> &str {
        &self.display
    }

    /// Run `texel` on this display (and no Wayland one).
    fn texel(&self, args: &[String]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_texel"))
            .args(args)
            .env("DISPLAY", &self.display)
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("cannot start the texel binary")
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn args(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// Run the viewer on `x` with `extra` arguments and write its last frame to `shot`.
fn view(x: &Xvfb, d: &Dir, shot: &str, extra: &[&str]) -> Image8 {
    let mut a = args(&["view", "builtin:ground", "--size", "320x180", "--no-hud"]);
    a.extend(args(extra));
    a.extend(["--screenshot".to_string(), d.arg(shot)]);
    let out = x.texel(&a);
    let err = stderr(&out);
    assert!(out.status.success(), "texel {a:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    load(d.join(shot))
}

fn render(d: &Dir, name: &str, extra: &[&str]) -> Image8 {
    let mut a = args(&[
        "render",
        "builtin:ground",
        "--size",
        "320x180",
        "-o",
        &d.arg(name),
    ]);
    a.extend(args(extra));
    ok(&a);
    load(d.join(name))
}

/// The pixels `[x0, x1) x [y0, y1)` of `image`.
fn crop(image: &Image8, [x0, y0, x1, y1]: [u32; 4]) -> Image8 {
    Image8::from_fn(x1 - x0, y1 - y0, |x, y| {
        image.pixel(x0 + x, y0 + y).expect("inside")
    })
    .unwrap()
}

/// The columns `x0..x1` of `image`.
fn columns(image: &Image8, x0: u32, x1: u32) -> Image8 {
    crop(image, [x0, 0, x1, image.height()])
}

#[test]
fn the_viewer_shows_what_render_writes() {
    let Some(x) = Xvfb::start() else { return };
    let d = Dir::new("view-render");
    let cases: [(&str, &[&str]); 3] = [
        ("5", &["--lab-mode", "5"]),
        ("1", &["--lab-mode", "1"]),
        (
            "4,q,v,v",
            &["--lab-mode", "4", "--derivatives", "quad", "--view", "mip"],
        ),
    ];
    for (k, (keys, render_args)) in cases.iter().enumerate() {
        let shot = view(
            &x,
            &d,
            &format!("s{k}.png"),
            &["--keys", keys, "--frames", "3"],
        );
        let want = render(&d, &format!("r{k}.png"), render_args);
        assert_eq!(shot.size(), (320, 180));
        let db = psnr(&shot, &want, None).unwrap();
        eprintln!("--keys {keys}: {db:.1} dB against texel render {render_args:?}");
        assert!(db >= 50.0, "--keys {keys}: {db:.1} dB");
    }
}

#[test]
fn split_screen_shows_each_halfs_filter() {
    let Some(x) = Xvfb::start() else { return };
    let d = Dir::new("view-split");
    let shot = view(
        &x,
        &d,
        "split.png",
        &["--keys", "2,shift+8", "--frames", "2"],
    );
    let bilinear = render(&d, "bilinear.png", &["--lab-mode", "2"]);
    let aniso = render(&d, "aniso.png", &["--lab-mode", "8"]);
    // The divider sits at half the width.
    for (x0, x1, want, other, name) in [
        (0, 160, &bilinear, &aniso, "left"),
        (160, 320, &aniso, &bilinear, "right"),
    ] {
        let half = columns(&shot, x0, x1);
        let db = psnr(&half, &columns(want, x0, x1), None).unwrap();
        let db_other = psnr(&half, &columns(other, x0, x1), None).unwrap();
        eprintln!("{name} half: {db:.1} dB against its filter, {db_other:.1} dB against the other");
        assert!(db >= 50.0, "{name} half: {db:.1} dB");
        assert!(
            db_other < 40.0,
            "{name} half looks like the other filter too: {db_other:.1} dB"
        );
    }
}

#[test]
fn the_reference_refines_frame_by_frame() {
    let Some(x) = Xvfb::start() else { return };
    let d = Dir::new("view-reference");
    let reference = {
        let a = args(&[
            "reference",
            "builtin:ground",
            "--size",
            "320x180",
            "--spp",
            "256",
            "--max-spp",
            "256",
            "-o",
            &d.arg("ref.png"),
        ]);
        ok(&a);
        load(d.join("ref.png"))
    };
    let few = view(&x, &d, "few.png", &["--keys", "0", "--frames", "1"]);
    let many = view(&x, &d, "many.png", &["--keys", "0", "--frames", "24"]);
    let (db_few, db_many) = (
        psnr(&few, &reference, None).unwrap(),
        psnr(&many, &reference, None).unwrap(),
    );
    eprintln!("reference in the viewer: 4 spp {db_few:.1} dB, 96 spp {db_many:.1} dB");
    // 24 times the samples: the noise's power falls about 24 times (13.8 dB) where noise
    // dominates; at least 6 dB over the whole image.
    assert!(db_many >= db_few + 6.0, "{db_few:.1} -> {db_many:.1} dB");
    assert!(db_many >= 30.0, "{db_many:.1} dB");
}

#[test]
fn the_hud_draws_over_the_frame_and_screenshots_name_the_state() {
    let Some(x) = Xvfb::start() else { return };
    let d = Dir::new("view-hud");
    let mut a = args(&[
        "view",
        "builtin:ground",
        "--size",
        "320x180",
        "--keys",
        "9,f12",
        "--frames",
        "1",
    ]);
    // F12 in a script writes the state's file name in the working directory.
    let out = Command::new(env!("CARGO_BIN_EXE_texel"))
        .args(a.drain(..))
        .current_dir(d.path())
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let shot = load(d.join("texel-ewa-color.png"));
    let plain = render(&d, "ewa.png", &["--filter", "ewa"]);
    // The HUD's panel darkens and writes over the top rows only (its lines are wider than
    // this small window); the ground below is the frame.
    let top = [0, 0, 320, 30];
    let bottom = [0, 120, 320, 180];
    let top_db = psnr(&crop(&shot, top), &crop(&plain, top), None).unwrap();
    let bottom_db = psnr(&crop(&shot, bottom), &crop(&plain, bottom), None).unwrap();
    assert!(top_db < 30.0, "no HUD drawn: {top_db:.1} dB");
    assert!(bottom_db >= 50.0, "{bottom_db:.1} dB");
}

#[test]
fn without_a_display_the_viewer_says_what_it_needs() {
    let out = Command::new(env!("CARGO_BIN_EXE_texel"))
        .args(["view", "--frames", "1"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("needs an X11 or Wayland display"), "{err}");
}

#[test]
fn a_bad_key_script_is_refused_before_any_window() {
    fails(
        &["view", "--keys", "1,ctrl+z", "--frames", "1"],
        1,
        &["--keys", "\"ctrl+z\" is not a key"],
    );
}

#[test]
fn with_gpu_the_viewer_shows_what_render_gpu_writes() {
    if !crate::gpu::have_adapter() {
        return;
    }
    let Some(x) = Xvfb::start() else { return };
    let d = Dir::new("view-gpu");
    // Mode 4 on the device; the ripmap (M) stays on the CPU, as the HUD says.
    let shot = view(
        &x,
        &d,
        "gpu.png",
        &["--gpu", "--keys", "4", "--frames", "2"],
    );
    let want = render(&d, "gpu-render.png", &["--gpu", "--lab-mode", "4"]);
    let db = psnr(&shot, &want, None).unwrap();
    eprintln!("--gpu --keys 4: {db:.1} dB against texel render --gpu --lab-mode 4");
    assert!(db >= 50.0, "{db:.1} dB");
    let shot = view(
        &x,
        &d,
        "ripmap.png",
        &["--gpu", "--keys", "m", "--frames", "1"],
    );
    let want = render(&d, "ripmap-render.png", &["--filter", "ripmap"]);
    assert!(psnr(&shot, &want, None).unwrap() >= 50.0);
}

/// The share of pixels of `a` and `b` within 6 codes in R, G and B (the lab's measure).
fn agree(a: &Image8, b: &Image8) -> f64 {
    let (pa, pb) = (a.pixels(), b.pixels());
    let ok = pa
        .iter()
        .zip(pb)
        .filter(|(x, y)| (0..3).all(|k| x[k].abs_diff(y[k]) <= 6))
        .count();
    ok as f64 / pa.len() as f64
}

/// `texel view --shader`: texel's GL solution in the window draws what texel's own mode draws
/// (quad derivatives, the same lab scene); Tab puts texel's mode on the right.
#[test]
fn shader_in_the_window_matches_texels_mode() {
    if !crate::lab::have_gl() {
        return;
    }
    let Some(x) = Xvfb::start() else { return };
    let d = Dir::new("view-shader");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scene = root.join("scenes/lab/tunnel.toml").display().to_string();
    let shader = root
        .join("crates/texel-lab/glsl/solution-gl.frag")
        .display()
        .to_string();
    let shot = |name: &str, extra: &[&str]| {
        let mut a = args(&[
            "view", &scene, "--size", "160x120", "--no-hud", "--frames", "2",
        ]);
        a.extend(args(extra));
        a.extend(["--screenshot".to_string(), d.arg(name)]);
        let out = x.texel(&a);
        let err = stderr(&out);
        assert!(out.status.success(), "texel {a:?}: {err}");
        load(d.join(name))
    };
    for mode in ["1", "4", "8"] {
        let keys = format!("q,{mode}");
        let ours = shot("ours.png", &["--keys", &keys]);
        let theirs = shot("shader.png", &["--keys", &keys, "--shader", &shader]);
        let a = agree(&ours, &theirs);
        assert!(a >= 0.97, "mode {mode}: {a}");
    }
}

/// A shader edited while the window runs is read again: here one that paints every pixel red,
/// then one that does not compile, which leaves the red one running. One that does not compile
/// at the start is refused before the window opens.
#[test]
fn shader_edits_are_picked_up_and_broken_ones_refused() {
    if !crate::lab::have_gl() {
        return;
    }
    let Some(x) = Xvfb::start() else { return };
    let d = Dir::new("view-shader-edit");
    let gl = include_str!("../../texel-lab/glsl/solution-gl.frag");
    let path = d.write("modes.frag", gl);
    let red = gl.replacen(
        "void main() {\n",
        "void main() {\n    if (texMode > 0) { fragColor = vec4(1.0, 0.0, 0.0, 1.0); return; }\n",
        1,
    );
    let shot = d.arg("edited.png");
    let a = args(&[
        "view",
        "builtin:ground",
        "--size",
        "96x54",
        "--no-hud",
        "--frames",
        "8000",
        "--keys",
        "4",
        "--shader",
        &path.display().to_string(),
        "--screenshot",
        &shot,
    ]);
    // About 1,700 frames a second here: the edit lands within the first tenth of the run.
    let child = Command::new(env!("CARGO_BIN_EXE_texel"))
        .args(&a)
        .env("DISPLAY", x.display())
        .env_remove("WAYLAND_DISPLAY")
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(400));
    std::fs::write(&path, &red).unwrap();
    // Then an edit that does not compile: the red one keeps running.
    std::thread::sleep(std::time::Duration::from_millis(400));
    std::fs::write(&path, "#version 330 core\nvoid main() { oops }\n").unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let img = load(d.join("edited.png"));
    let red_px = img
        .pixels()
        .iter()
        .filter(|p| p[0] == 255 && p[1] == 0 && p[2] == 0)
        .count();
    // The ground covers the frame below the horizon.
    assert!(red_px * 3 > img.pixels().len(), "{red_px} red pixels");

    let out = x.texel(&args(&[
        "view",
        "builtin:ground",
        "--frames",
        "1",
        "--shader",
        &path.display().to_string(),
    ]));
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("does not compile"), "{err}");
}
