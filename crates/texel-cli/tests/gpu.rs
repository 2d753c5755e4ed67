//! `render --gpu` and `gpu-info`. The rendering tests need a Vulkan adapter (Mesa's lavapipe:
//! `apt-get install mesa-vulkan-drivers`); without one they print why and pass, unless `CI=true`.

use texel::quality::Image8;

use crate::util::*;

/// Whether the machine has a Vulkan adapter; panics under `CI=true` when it has none. A GL adapter
/// alone does not count: GLSL ES has no fine derivatives, so on GL the mip-nearest and trilinear
/// images differ from the CPU's in a few quads (the agreement bound holds on Vulkan), and these
/// tests skip there.
pub(crate) fn have_adapter() -> bool {
    if texel_gpu::adapters().iter().any(|a| a.backend == "Vulkan") {
        return true;
    }
    assert_ne!(
        std::env::var("CI").as_deref(),
        Ok("true"),
        "CI=true but no Vulkan adapter: install mesa-vulkan-drivers"
    );
    eprintln!("skipped: no Vulkan adapter (apt-get install mesa-vulkan-drivers)");
    false
}

#[test]
fn gpu_refuses_filters_it_does_not_have() {
    let d = Dir::new("gpu-ripmap");
    let out = texel(&[
        "render",
        "--gpu",
        "--filter",
        "ripmap",
        "-o",
        &d.arg("x.png"),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("--gpu has no ripmap filter"), "{err}");
    assert!(
        err.contains("bicubic, mip-nearest")
            && err.contains("aniso16, ewa")
            && !err.contains("panicked"),
        "{err}"
    );
}

/// `--convention lab --gpu` renders the handout's formulas in the shader: the image is the CPU's
/// under the same convention (2x2-quad derivatives, as the device's) to within a code on nearly
/// every pixel, and not the GL rules' image.
#[test]
fn gpu_renders_the_lab_convention() {
    if !have_adapter() {
        return;
    }
    let d = Dir::new("gpu-convention");
    let run = |name: &str, extra: &[&str]| {
        let png = d.arg(name);
        let mut args = vec![
            "render",
            "builtin:ground",
            "--lab-mode",
            "6",
            "--size",
            "96x64",
        ];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", &png]);
        let out = texel(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        Image8::load(&png).unwrap()
    };
    let gpu_lab = run("gpu-lab.png", &["--gpu", "--convention", "lab"]);
    let cpu_lab = run(
        "cpu-lab.png",
        &["--convention", "lab", "--derivatives", "quad"],
    );
    let gpu_gl = run("gpu-gl.png", &["--gpu"]);
    let close = |a: &Image8, b: &Image8| {
        let near = a
            .pixels()
            .iter()
            .zip(b.pixels())
            .filter(|(p, q)| (0..3).all(|c| p[c].abs_diff(q[c]) <= 1))
            .count();
        near as f64 / a.pixels().len() as f64
    };
    let same = close(&gpu_lab, &cpu_lab);
    let other = close(&gpu_lab, &gpu_gl);
    eprintln!("within a code: gpu lab vs cpu lab {same:.4}, vs gpu gl {other:.4}");
    assert!(same >= 0.99, "{same}");
    assert!(other < 0.9, "{other}");
}

#[test]
fn gpu_names_the_adapters_when_the_requested_one_is_missing() {
    let d = Dir::new("gpu-adapter");
    let out = texel(&[
        "render",
        "--gpu",
        "--adapter",
        "no-such-device",
        "-o",
        &d.arg("x.png"),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("no GPU adapter named like \"no-such-device\"; available:")
            || err.contains("no GPU adapter found"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(!d.join("x.png").exists());
}

#[test]
fn gpu_renders_the_lab_modes() {
    if !have_adapter() {
        return;
    }
    let d = Dir::new("gpu-render");
    for mode in ["1", "4", "8"] {
        let png = d.arg(&format!("lab{mode}.png"));
        let out = texel(&[
            "render",
            "builtin:ground",
            "--gpu",
            "--lab-mode",
            mode,
            "--size",
            "96x64",
            "-o",
            &png,
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        let img = Image8::load(&png).unwrap();
        assert_eq!(img.size(), (96, 64));
        // The ground covers the lower half: it is not all background.
        assert!(img.pixels().iter().skip(96 * 40).any(|p| p[0] > 0));
    }
    let out = texel(&["gpu-info"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("--gpu uses:"));
    // Headless (no display, no runtime directory), a command that succeeds prints no error line:
    // Mesa's device-select layer would try a Wayland connection and print one.
    let headless = std::process::Command::new(env!("CARGO_BIN_EXE_texel"))
        .arg("gpu-info")
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("DISPLAY")
        .env_remove("NODEVICE_SELECT")
        .output()
        .unwrap();
    assert!(headless.status.success());
    assert!(
        !stderr(&headless).contains("error"),
        "{}",
        stderr(&headless)
    );
}

#[test]
fn compare_gpu_scores_shader_and_hardware_rows() {
    if !have_adapter() {
        return;
    }
    let d = Dir::new("gpu-compare");
    let out = texel(&[
        "compare",
        "builtin:ground",
        "--size",
        "96x64",
        "--spp",
        "16",
        "--filters",
        "trilinear,aniso16",
        "--gpu",
        "--sampled-reference",
        "--out",
        &d.arg("report"),
    ]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    let md = String::from_utf8_lossy(&out.stdout).into_owned();
    let psnr = |row: &str| -> f64 {
        let line = md
            .lines()
            .find(|l| l.starts_with(&format!("| {row} ")))
            .unwrap_or_else(|| panic!("no row {row}: {md}"));
        line.split('|').nth(2).unwrap().trim().parse().unwrap()
    };
    // texel's shaders filter as the CPU does: the images are close to each other (41.6 and
    // 37.7 dB apart on lavapipe), and their scores against the 16-sample reference agree to a
    // quarter of a dB.
    for f in ["trilinear", "aniso16"] {
        let (cpu, gpu) = (psnr(f), psnr(&format!("gpu-{f} (extra)")));
        assert!((cpu - gpu).abs() < 0.25, "{f}: cpu {cpu} gpu {gpu}");
        let image = |name: &str| load(d.join("report").join(format!("{name}.png")));
        let apart = texel::quality::psnr(&image(f), &image(&format!("gpu-{f}")), None).unwrap();
        assert!(apart > 35.0, "{f}: cpu and gpu images {apart} dB apart");
    }
    assert!(psnr("hw-trilinear (extra)") > 0.0 && psnr("hw-aniso16 (extra)") > 0.0);
}

#[test]
fn bench_gpu_times_shaders_and_the_hardware_sampler() {
    // The list is checked before an adapter is looked for: no Vulkan needed for the refusal.
    let out = texel(&["bench", "--gpu", "--filters", "trilinear,sat"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--gpu has no sat filter")
            && err.contains("ewa, ewa-probes, hw-trilinear, hw-aniso16)"),
        "{err}"
    );
    // `all` only alone; an unknown name gets the GPU's own list.
    for list in ["hw-trilinear,all", "hw-aniso8"] {
        let out = texel(&["bench", "--gpu", "--filters", list]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(
            err.contains("for --gpu: valid are nearest,") && err.contains("hw-aniso16, or all"),
            "{err}"
        );
    }
    if !have_adapter() {
        return;
    }
    let out = texel(&[
        "bench",
        "builtin:ground",
        "--gpu",
        "--size",
        "96x64",
        "--frames",
        "2",
        "--warmup",
        "0",
        "--filters",
        "hw-aniso16,trilinear,HW-trilinear,hw-aniso16",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    // Once in `median_ms` and once in `device_ms`: the repeated names ran once.
    for row in ["\"hw-trilinear\":", "\"hw-aniso16\":", "\"trilinear\":"] {
        assert_eq!(text.matches(row).count(), 2, "{row} in {text}");
    }
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["renderer"], "texel-gpu");
    assert!(
        json["adapter"].as_str().unwrap().contains("Vulkan"),
        "{json}"
    );
    let mut rows: Vec<&String> = json["median_ms"].as_object().unwrap().keys().collect();
    rows.sort();
    // Each row once, the hardware label's case ignored.
    assert_eq!(rows, ["hw-aniso16", "hw-trilinear", "trilinear"], "{json}");
    // lavapipe has timestamp queries: every row has a device time from its passes.
    let timestamps = json["adapter"].as_str().unwrap().contains("llvmpipe");
    for row in rows {
        assert!(json["median_ms"][row].as_f64().unwrap() > 0.0, "{json}");
        let device = json["device_ms"][row].as_f64().unwrap();
        assert!(device > 0.0 || (!timestamps && device == 0.0), "{json}");
    }
}
