//! Hostile input, as an attacker or a careless script would give it: output paths that are not
//! regular files, interrupted runs, inputs that multiply (glTF DAGs, lying buffers), images whose
//! headers promise more than memory allows, FIFOs where files belong, NaN texels, truncated files,
//! empty meshes, and the error messages each one gets. Every case: a clear one-line error and a
//! non-zero exit (or the documented success), never a panic, a hang or a replaced special file.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::util::*;

/// Run `texel` with `args`, killing it (and failing the test) if it runs over `limit`: a hang is
/// a failure, not a stuck test suite.
fn texel_within(args: &[&str], limit: Duration) -> std::process::Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_texel"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("texel {args:?} hung for over {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// A scene of [`HEAD`] whose texture `t` is replaced by the file `path`, drawing [`TRIANGLE`].
fn scene_with_texture(path: &Path) -> String {
    let head = HEAD.replace(
        "procedural = \"checker\"\nsize = 64\nchecks = 4\n",
        &format!("path = {:?}\n", path.to_string_lossy()),
    );
    format!("{head}{TRIANGLE}")
}

fn scene_with_mesh(mesh: &str) -> String {
    format!("{HEAD}\n[[meshes]]\ntexture = \"t\"\n{mesh}\n")
}

/// A PNG of `width x height` 1-bit grey pixels, all black: tiny on disk, huge when decoded.
fn bilevel_png(width: u32, height: u32) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::One);
    enc.set_compression(png::Compression::Fast);
    let mut w = enc.write_header().unwrap();
    let mut stream = w.stream_writer().unwrap();
    let row = vec![0u8; width.div_ceil(8) as usize];
    for _ in 0..height {
        std::io::Write::write_all(&mut stream, &row).unwrap();
    }
    stream.finish().unwrap();
    drop(w);
    out
}

/// A baseline JPEG of a 64x64 gradient.
fn small_jpeg() -> Vec<u8> {
    let img = image::RgbImage::from_fn(64, 64, |x, y| {
        image::Rgb([(x * 4) as u8, (y * 4) as u8, 99])
    });
    let mut out = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, 90)
        .encode_image(&img)
        .unwrap();
    out
}

#[cfg(unix)]
fn is_char_device(p: &str) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::symlink_metadata(p)
        .unwrap()
        .file_type()
        .is_char_device()
}

// ---------------------------------------------------------------------------------------------
// 1. Output paths
// ---------------------------------------------------------------------------------------------

#[cfg(target_os = "linux")]
#[test]
fn devices_are_written_through_never_replaced() {
    // Run as root, a rename over /dev/null would replace the system's /dev/null with a PNG.
    ok(&["render", "--size", "16x9", "-o", "/dev/null"]);
    assert!(is_char_device("/dev/null"));
    fails(
        &["render", "--size", "16x9", "-o", "/dev/full"],
        1,
        &["/dev/full", "No space left on device"],
    );
    assert!(is_char_device("/dev/full"));
}

#[test]
fn dash_streams_the_png_to_stdout() {
    let out = ok(&["render", "--size", "20x10", "-o", "-"]);
    let img = image::load_from_memory(&out.stdout).expect("a PNG on stdout");
    assert_eq!((img.width(), img.height()), (20, 10));
}

#[cfg(unix)]
#[test]
fn symlinks_fifos_and_long_names() {
    let d = Dir::new("hostile-outpaths");
    // A symbolic link: its target is written, the link stays.
    std::fs::create_dir_all(d.join("real")).unwrap();
    std::os::unix::fs::symlink("real/target.png", d.join("link.png")).unwrap();
    ok(&["render", "--size", "16x9", "-o", &d.arg("link.png")]);
    assert!(std::fs::symlink_metadata(d.join("link.png"))
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(load(d.join("real/target.png")).size(), (16, 9));
    // A FIFO is written through to its reader.
    let fifo = d.join("pipe.png");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            std::fs::File::open(fifo)
                .unwrap()
                .read_to_end(&mut bytes)
                .unwrap();
            bytes
        })
    };
    let out = texel_within(
        &["render", "--size", "12x6", "-o", &d.arg("pipe.png")],
        Duration::from_secs(60),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let bytes = reader.join().unwrap();
    assert_eq!(image::load_from_memory(&bytes).unwrap().width(), 12);
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_file()
        .eq(&false));
    // A 250-byte file name the file system takes works: the temporary name does not grow with it.
    let long = "n".repeat(246) + ".png";
    ok(&["render", "--size", "8x8", "-o", &d.arg(&long)]);
    assert_eq!(load(d.join(&long)).size(), (8, 8));
    // A directory is refused.
    fails(
        &["render", "--size", "8x8", "-o", &d.arg("real")],
        1,
        &["is a directory"],
    );
    assert!(temp_files(d.path()).is_empty());
}

/// Wait until `dir` holds a hidden `.texel-*` staging entry (a run is under way), up to 60 s.
fn wait_for_staging(dir: &Path) -> bool {
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(60) {
        let any = std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .any(|e| e.file_name().to_string_lossy().starts_with(".texel-"));
        if any {
            return true;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    false
}

fn hidden(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect()
}

/// Start a long `compare` into `out`, wait for its staging directory, send `signal`; return the
/// exit status.
#[cfg(unix)]
fn interrupted_compare(d: &Dir, out: &str, signal: &str) -> std::process::ExitStatus {
    let mut child = Command::new(env!("CARGO_BIN_EXE_texel"))
        .args([
            "compare",
            "--size",
            "640x360",
            "--spp",
            "4096",
            "--filters",
            "ewa",
            "--out",
            out,
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    assert!(wait_for_staging(d.path()), "no staging directory appeared");
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args([signal, &pid])
        .status()
        .unwrap()
        .success());
    child.wait().unwrap()
}

#[cfg(unix)]
#[test]
fn interrupted_runs_leave_no_temporaries_and_reports_are_whole() {
    let d = Dir::new("hostile-signals");
    let out = d.arg("report");
    // A first, complete report.
    ok(&[
        "compare",
        "--size",
        "32x18",
        "--spp",
        "1",
        "--filters",
        "nearest",
        "--out",
        &out,
    ]);
    let first = std::fs::read(d.join("report/index.html")).unwrap();
    // SIGTERM and SIGINT: the handler deletes the staging directory; the old report is intact.
    for signal in ["-TERM", "-INT"] {
        let status = interrupted_compare(&d, &out, signal);
        assert_eq!(status.code(), Some(130), "{signal}");
        assert!(
            hidden(d.path()).is_empty(),
            "{signal}: {:?}",
            hidden(d.path())
        );
        assert_eq!(std::fs::read(d.join("report/index.html")).unwrap(), first);
        assert!(d.join("report/nearest.png").exists());
    }
    // SIGKILL cannot be handled: the staging directory stays, the old report is still whole, and
    // the next publish to the same path removes the leftover.
    let status = interrupted_compare(&d, &out, "-KILL");
    assert!(!status.success());
    assert_eq!(hidden(d.path()).len(), 1);
    assert_eq!(std::fs::read(d.join("report/index.html")).unwrap(), first);
    ok(&[
        "compare",
        "--size",
        "32x18",
        "--spp",
        "1",
        "--filters",
        "bilinear",
        "--out",
        &out,
    ]);
    assert!(hidden(d.path()).is_empty(), "{:?}", hidden(d.path()));
    // The new report replaced the old one as a whole: no image of the first run survives.
    assert!(d.join("report/bilinear.png").exists());
    assert!(!d.join("report/nearest.png").exists());
}

#[test]
fn report_directories_are_replaced_only_when_texel_wrote_them() {
    let d = Dir::new("hostile-outdir");
    // compare --out onto a file: a clear message, not "File exists (os error 17)".
    d.write("file", b"keep");
    fails(
        &[
            "compare",
            "--size",
            "16x12",
            "--spp",
            "1",
            "--filters",
            "nearest",
            "--out",
            &d.arg("file"),
        ],
        1,
        &["exists and is not a directory"],
    );
    assert_eq!(std::fs::read(d.join("file")).unwrap(), b"keep");
    // A directory holding someone else's files is left alone.
    std::fs::create_dir_all(d.join("notes")).unwrap();
    d.write("notes/todo.txt", b"mine");
    fails(
        &["mips", &d.arg("notes/todo.txt"), "--out", &d.arg("notes")],
        1,
        &[],
    );
    let img = image::RgbaImage::from_pixel(4, 4, image::Rgba([1, 2, 3, 255]));
    img.save(d.join("src.png")).unwrap();
    fails(
        &["mips", &d.arg("src.png"), "--out", &d.arg("notes")],
        1,
        &["did not write"],
    );
    assert_eq!(std::fs::read(d.join("notes/todo.txt")).unwrap(), b"mine");
    // An empty directory, and texel's own output, are fine.
    std::fs::create_dir_all(d.join("empty")).unwrap();
    ok(&["mips", &d.arg("src.png"), "--out", &d.arg("empty")]);
    ok(&["mips", &d.arg("src.png"), "--out", &d.arg("empty")]);
    assert!(d.join("empty/level-02-1x1.png").exists());
}

// ---------------------------------------------------------------------------------------------
// 2. Inputs that multiply
// ---------------------------------------------------------------------------------------------

/// A glTF whose `depth` levels of two nodes each both point at both nodes of the next level: a
/// DAG that instantiates the quad 2^depth times if walked as a tree.
fn dag_gltf(depth: usize, buffer_uri: &str) -> String {
    let mut nodes = Vec::new();
    for level in 0..depth {
        let children = if level + 1 < depth {
            format!(", \"children\": [{}, {}]", 2 * level + 2, 2 * level + 3)
        } else {
            String::new()
        };
        for _ in 0..2 {
            nodes.push(format!("{{\"mesh\": 0{children}}}"));
        }
    }
    quad_gltf(buffer_uri)
        .replace(
            "\"scenes\": [{\"nodes\": [0]}]",
            "\"scenes\": [{\"nodes\": [0, 1]}]",
        )
        .replace(
            "\"nodes\": [{\"mesh\": 0}]",
            &format!("\"nodes\": [{}]", nodes.join(", ")),
        )
}

#[test]
fn gltf_dags_and_lying_buffers_are_refused_before_they_cost() {
    let d = Dir::new("hostile-gltf");
    d.write("quad.bin", quad_buffer());
    let scene = |name: &str| scene_with_mesh(&format!("gltf = {:?}", d.arg(name)));
    // 40 levels would be 2^41 instances; refused at once.
    d.write("dag.gltf", dag_gltf(40, "quad.bin"));
    d.write("dag.toml", scene("dag.gltf"));
    let out = texel_within(
        &["render", &d.arg("dag.toml"), "-o", &d.arg("x.png")],
        Duration::from_secs(30),
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("is a child of both node"),
        "{}",
        stderr(&out)
    );
    // A buffer naming a device is refused; one naming a larger file is read only up to
    // byteLength (and renders).
    #[cfg(target_os = "linux")]
    {
        d.write("zero.gltf", quad_gltf("/dev/zero"));
        d.write("zero.toml", scene("zero.gltf"));
        let out = texel_within(
            &["render", &d.arg("zero.toml"), "-o", &d.arg("x.png")],
            Duration::from_secs(30),
        );
        assert_eq!(out.status.code(), Some(1));
        assert!(
            stderr(&out).contains("character device"),
            "{}",
            stderr(&out)
        );
    }
    let mut big = quad_buffer();
    big.resize(8 << 20, 0xAB);
    d.write("big.bin", big);
    d.write("big.gltf", quad_gltf("big.bin"));
    d.write("big.toml", scene("big.gltf"));
    ok(&["render", &d.arg("big.toml"), "-o", &d.arg("big.png")]);
    // A buffer shorter than its byteLength is an error with both figures.
    d.write("short.bin", &quad_buffer()[..50]);
    d.write("short.gltf", quad_gltf("short.bin"));
    d.write("short.toml", scene("short.gltf"));
    fails(
        &["render", &d.arg("short.toml"), "-o", &d.arg("x.png")],
        1,
        &["byteLength 92", "only 50 bytes"],
    );
    // Embedded data still works, and a URI with invalid percent-encoding is an error, not a panic.
    d.write(
        "embedded.gltf",
        quad_gltf(&format!(
            "data:application/octet-stream;base64,{}",
            base64(&quad_buffer())
        )),
    );
    d.write("embedded.toml", scene("embedded.gltf"));
    ok(&["render", &d.arg("embedded.toml"), "-o", &d.arg("e.png")]);
    d.write("pct.gltf", quad_gltf("%FF%FE.bin"));
    d.write("pct.toml", scene("pct.gltf"));
    fails(
        &["render", &d.arg("pct.toml"), "-o", &d.arg("x.png")],
        1,
        &["not valid UTF-8"],
    );
}

// ---------------------------------------------------------------------------------------------
// 3. Allocation
// ---------------------------------------------------------------------------------------------

#[test]
fn images_over_the_memory_budget_are_refused_with_figures() {
    let d = Dir::new("hostile-memory");
    // A few hundred KB of PNG that decodes to 16384 x 16384.
    let png = d.write("huge.png", bilevel_png(16384, 16384));
    assert!(std::fs::metadata(&png).unwrap().len() < 2 << 20);
    let err = fails(
        &[
            "mips",
            &d.arg("huge.png"),
            "--max-memory",
            "1G",
            "--out",
            &d.arg("m"),
        ],
        1,
        &["16384x16384", "MiB", "--max-memory 1024.0 MiB"],
    );
    assert!(err.contains("bytes"), "{err}");
    assert!(!d.join("m").exists());
    // A frame larger than the budget.
    fails(
        &[
            "render",
            "--size",
            "16384x16384",
            "--max-memory",
            "256M",
            "-o",
            &d.arg("f.png"),
        ],
        1,
        &["16384x16384 frame needs about", "--max-memory 256.0 MiB"],
    );
    // A JPEG of a few hundred bytes whose header claims 16000 x 16000.
    let mut jpeg = small_jpeg();
    let sof = jpeg.windows(2).position(|w| w == [0xFF, 0xC0]).unwrap();
    jpeg[sof + 5..sof + 9].copy_from_slice(&[0x3E, 0x80, 0x3E, 0x80]);
    d.write("liar.jpg", &jpeg);
    fails(
        &["mips", &d.arg("liar.jpg"), "--out", &d.arg("m")],
        1,
        &["16000x16000 JPEG", "needs at least"],
    );
    // Usage errors for the flag itself.
    fails(
        &["render", "--max-memory", "12Q", "-o", "x.png"],
        2,
        &["unknown unit"],
    );
}

// ---------------------------------------------------------------------------------------------
// 4. Hangs
// ---------------------------------------------------------------------------------------------

#[cfg(unix)]
#[test]
fn fifos_where_files_belong_are_refused_at_once() {
    let d = Dir::new("hostile-fifo");
    let fifo = d.join("f");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let limit = Duration::from_secs(30);
    let f = d.arg("f");
    d.write("tex.toml", scene_with_texture(&fifo));
    d.write("obj.toml", scene_with_mesh(&format!("obj = {f:?}")));
    d.write("gltf.toml", scene_with_mesh(&format!("gltf = {f:?}")));
    let (png, tex, obj, gltf) = (
        d.arg("o.png"),
        d.arg("tex.toml"),
        d.arg("obj.toml"),
        d.arg("gltf.toml"),
    );
    let (mips, cmp, extra) = (d.arg("m"), d.arg("c"), format!("x={f}"));
    let compare = compare_extra(&extra, &cmp);
    let compare: Vec<&str> = compare.iter().map(String::as_str).collect();
    let cases: [&[&str]; 7] = [
        &["render", &f, "-o", &png],
        &["render", &tex, "-o", &png],
        &["render", &obj, "-o", &png],
        &["render", &gltf, "-o", &png],
        &["mips", &f, "--out", &mips],
        &["warp", &f, "--corners", "0,0,1,0,1,1,0,1", "-o", &png],
        &compare,
    ];
    for args in cases {
        let out = texel_within(args, limit);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains("FIFO"), "{args:?}: {}", stderr(&out));
    }
    // Count arguments are bounded, and the bound is in --help.
    fails(&["bench", "--warmup", "4294967295"], 2, &["0..=10000"]);
    let help = stdout(&ok(&["bench", "--help"]));
    assert!(help.contains("0 to 10000"), "{help}");
}

// ---------------------------------------------------------------------------------------------
// 5. Silent success on bad data
// ---------------------------------------------------------------------------------------------

#[test]
fn non_finite_texels_are_named_or_replaced() {
    let d = Dir::new("hostile-nan");
    let mut img = image::Rgba32FImage::from_pixel(8, 4, image::Rgba([0.5, 0.25, 0.125, 1.0]));
    img.put_pixel(3, 2, image::Rgba([0.5, f32::NAN, 0.1, 1.0]));
    img.put_pixel(5, 1, image::Rgba([f32::INFINITY, 0.0, 0.1, 1.0]));
    image::DynamicImage::ImageRgba32F(img)
        .save(d.join("bad.exr"))
        .unwrap();
    // The first in row order is (5, 1).
    fails(
        &["mips", &d.arg("bad.exr"), "--out", &d.arg("m")],
        1,
        &["texel (5, 1) channel R is inf", "--sanitize"],
    );
    let out = ok(&[
        "mips",
        &d.arg("bad.exr"),
        "--sanitize",
        "--out",
        &d.arg("m"),
    ]);
    assert!(
        stderr(&out).contains("replaced 2 NaN, infinite or out-of-range"),
        "{}",
        stderr(&out)
    );
    // The 1x1 level is the mean with NaN -> 0 and inf -> 65504: red saturates, green is finite.
    let top = load(d.join("m/level-03-1x1.png"));
    assert_eq!(top.pixel(0, 0).unwrap()[0], 255);
    // Scenes refuse them too.
    d.write("nan.toml", scene_with_texture(&d.join("bad.exr")));
    fails(
        &["render", &d.arg("nan.toml"), "-o", &d.arg("x.png")],
        1,
        &["textures.t", "texel (5, 1)"],
    );
    ok(&[
        "render",
        &d.arg("nan.toml"),
        "--sanitize",
        "-o",
        &d.arg("x.png"),
    ]);
}

#[test]
fn decoder_panics_are_one_line_errors() {
    // A JPEG that makes the image crate's JPEG decoder (zune-jpeg 0.5.15, AVX2 path) panic.
    let jpg = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../texel-texture/tests/data/zune-avx2-idct-panic.jpg"
    );
    let d = Dir::new("hostile-decoder-panic");
    let out = texel(&["mips", jpg, "--out", &d.arg("m")]);
    let err = stderr(&out);
    assert!(!err.contains("panicked"), "{err}");
    if !out.status.success() {
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

#[test]
fn truncated_images_are_errors() {
    let d = Dir::new("hostile-trunc");
    let jpeg = small_jpeg();
    d.write("cut.jpg", &jpeg[..jpeg.len() * 6 / 10]);
    fails(
        &["mips", &d.arg("cut.jpg"), "--out", &d.arg("m")],
        1,
        &["truncated image", "end-of-image marker"],
    );
    d.write("whole.jpg", &jpeg);
    ok(&["mips", &d.arg("whole.jpg"), "--out", &d.arg("m")]);
    let mut png = Vec::new();
    image::RgbaImage::from_fn(64, 64, |x, y| {
        image::Rgba([x as u8 * 3, y as u8 * 5, 7, 255])
    })
    .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
    .unwrap();
    d.write("cut.png", &png[..png.len() / 2]);
    fails(
        &["mips", &d.arg("cut.png"), "--out", &d.arg("m2")],
        1,
        &["cut.png"],
    );
    assert!(!d.join("m2").exists());
}

#[test]
fn meshes_without_triangles_are_errors_naming_the_file() {
    let d = Dir::new("hostile-empty");
    let cases = [
        ("empty.obj", "", "no triangles"),
        (
            "points.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\n",
            "no triangles",
        ),
        (
            "lines.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nl 1/1 2/2\n",
            "no triangles",
        ),
    ];
    for (name, text, needle) in cases {
        d.write(name, text);
        d.write(
            "s.toml",
            scene_with_mesh(&format!("obj = {:?}", d.arg(name))),
        );
        fails(
            &["render", &d.arg("s.toml"), "-o", &d.arg("x.png")],
            1,
            &[name, needle],
        );
    }
    // An OBJ parse error names its line.
    d.write(
        "bad.obj",
        "v 0 0 0\nv 1 0 0\nv 0 x 0\nvt 0 0\nf 1/1 2/1 3/1\n",
    );
    d.write(
        "s.toml",
        scene_with_mesh(&format!("obj = {:?}", d.arg("bad.obj"))),
    );
    fails(
        &["render", &d.arg("s.toml"), "-o", &d.arg("x.png")],
        1,
        &["bad.obj", "line 3 (\"v 0 x 0\")", "position parse error"],
    );
    d.write("q.obj", QUAD_OBJ);
    d.write(
        "s.toml",
        scene_with_mesh(&format!("obj = {:?}", d.arg("q.obj"))),
    );
    ok(&["render", &d.arg("s.toml"), "-o", &d.arg("q.png")]);
    // A scene without meshes, or with an empty inline mesh, draws nothing: an error.
    d.write("none.toml", HEAD);
    fails(
        &["render", &d.arg("none.toml"), "-o", &d.arg("x.png")],
        1,
        &["no meshes"],
    );
    d.write(
        "emptymesh.toml",
        scene_with_mesh("positions = [[0.0, 0.0, 0.0]]\nuvs = [[0.0, 0.0]]\ntriangles = []"),
    );
    fails(
        &["render", &d.arg("emptymesh.toml"), "-o", &d.arg("x.png")],
        1,
        &["meshes[0] has no triangles"],
    );
}

// ---------------------------------------------------------------------------------------------
// 6. Misleading errors
// ---------------------------------------------------------------------------------------------

#[test]
fn errors_name_the_real_cause() {
    let d = Dir::new("hostile-errors");
    // --spp: the help's range is the real one.
    fails(
        &["reference", "--spp", "5000", "-o", "x.png"],
        2,
        &["1..=4096"],
    );
    let help = stdout(&ok(&["reference", "--help"]));
    assert!(help.contains("1 to 4096"), "{help}");
    // warp without --size on a source too large to be the output: said at once, about the source.
    d.write("wide.png", bilevel_png(16384, 4200));
    let out = texel_within(
        &[
            "warp",
            &d.arg("wide.png"),
            "--corners",
            "0,0,10,0,10,10,0,10",
            "-o",
            &d.arg("w.png"),
        ],
        Duration::from_secs(20),
    );
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("source is 16384x4200 and no --size was given"),
        "{err}"
    );
    // Two --extra entries with one label.
    let img = d.arg("e.png");
    image::RgbaImage::from_pixel(16, 9, image::Rgba([0, 0, 0, 255]))
        .save(&img)
        .unwrap();
    fails(
        &[
            "compare",
            "--size",
            "16x9",
            "--spp",
            "1",
            "--filters",
            "nearest",
            "--extra",
            &format!("a b={img}"),
            "--extra",
            &format!("a_b={img}"),
            "--out",
            &d.arg("c"),
        ],
        1,
        &["extra-a_b.png"],
    );
    // An --extra image of another size is refused from its header, before it is decoded.
    fails(
        &compare_extra(&format!("gpu={img}"), &d.arg("c2")),
        1,
        &["is 16x9 but the comparison is 32x18"],
    );
}
