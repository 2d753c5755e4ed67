//! `texel compare`: the report agrees with the images it wrote; the filter ranking on the ground plane.

use texel::quality::{
    block_psnr, psnr, psnr_band, ssim, Encoding, Image8, Mask, Report, DEFAULT_BLOCK, OUTSIDE,
};

use crate::util::*;

/// The coverage mask as the report used it, read back from a heat map: [`OUTSIDE`] marks the
/// uncovered pixels and viridis never reaches it.
fn coverage_from_heat_map(heat: &Image8) -> Mask {
    let bits = heat.pixels().iter().map(|p| *p != OUTSIDE).collect();
    Mask::new(heat.width(), heat.height(), bits).unwrap()
}

fn close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
}

#[test]
fn compare_report_is_consistent_with_its_images() {
    let d = Dir::new("compare");
    // An image rendered elsewhere: texel's own bilinear image at the same size.
    let extra = d.arg("elsewhere.png");
    ok(&[
        "render", "--size", "96x54", "--filter", "bilinear", "-o", &extra,
    ]);
    let out = d.join("report");
    let out_s = out.to_string_lossy().into_owned();
    let run = ok(&[
        "compare",
        "builtin:ground",
        "--size",
        "96x54",
        "--spp",
        "16",
        "--filters",
        "nearest,bilinear,trilinear,ewa",
        "--extra",
        &format!("gpu={extra}"),
        // The sampled reference everywhere: this test is about its noise.
        "--sampled-reference",
        "--out",
        &out_s,
    ]);
    // The Markdown table goes to stdout, the report's place to stderr.
    assert!(stdout(&run).contains("| trilinear |"), "{}", stdout(&run));
    assert!(stderr(&run).contains("index.html"));

    let report =
        Report::from_json(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!((report.width, report.height, report.spp), (96, 54, 16));
    assert_eq!(report.color, "srgb");
    let names: Vec<&str> = report.rows.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["nearest", "bilinear", "trilinear", "ewa", "gpu"]);
    let reference = load(out.join(&report.reference_image));
    assert_eq!(reference.size(), (96, 54));

    let mut coverage: Option<Mask> = None;
    for row in &report.rows {
        let image = load(out.join(&row.image));
        let heat = load(out.join(row.heat_map.as_ref().expect("every row has a heat map")));
        let mask = coverage_from_heat_map(&heat);
        // Every heat map shows the same coverage, part of the image (the plane below the horizon).
        match &coverage {
            None => {
                assert!(
                    mask.count() > 0 && mask.count() < 96 * 54,
                    "coverage {} pixels",
                    mask.count()
                );
                assert!(mask.get(48, 53) && !mask.get(48, 0));
                coverage = Some(mask.clone());
            }
            Some(c) => assert_eq!(&mask, c, "{}: another coverage", row.name),
        }
        // The scores are exactly those of the images written.
        let p = psnr(&reference, &image, Some(&mask)).unwrap();
        assert!(
            close(row.psnr_all, p),
            "{}: psnr_all {} but the images give {p}",
            row.name,
            row.psnr_all
        );
        let b = psnr_band(&reference, &image, &mask, report.band_rows).unwrap();
        assert!(
            close(row.psnr_band, b),
            "{}: psnr_band {} but the images give {b}",
            row.name,
            row.psnr_band
        );
        let k = block_psnr(
            &reference,
            &image,
            Some(&mask),
            DEFAULT_BLOCK,
            Encoding::Srgb,
        )
        .unwrap();
        assert!(
            row.psnr_block.is_some_and(|v| close(v, k)),
            "{}: psnr_block {:?} but the images give {k}",
            row.name,
            row.psnr_block
        );
        // Block means hide per-pixel noise and aliasing: never a lower score than per pixel
        // by more than the re-encoding's rounding.
        assert!(
            k >= row.psnr_all - 0.5,
            "{}: blocks {k} < pixels {}",
            row.name,
            row.psnr_all
        );
        // The reference cannot rank two rows one way and not the other.
        for other in &row.within_noise_of {
            let o = report.rows.iter().find(|r| &r.name == other).unwrap();
            assert!(
                o.within_noise_of.contains(&row.name),
                "{} / {other}",
                row.name
            );
        }
        let s = ssim(&reference, &image, Some(&mask)).unwrap();
        assert!(
            close(row.ssim, s),
            "{}: ssim {} but the images give {s}",
            row.name,
            row.ssim
        );
        assert!(
            row.psnr_all.is_finite() && row.psnr_all > 5.0,
            "{}: {}",
            row.name,
            row.psnr_all
        );
        if let Some(crop) = &row.horizon_crop {
            assert!(out.join(crop).is_file());
        }
        if row.extra {
            assert!(
                row.ms_per_frame.is_none()
                    && row.texels_per_pixel_mean.is_none()
                    && row.texture_bytes.is_none()
            );
        } else {
            assert!(row.ms_per_frame.is_some_and(|ms| ms > 0.0), "{}", row.name);
            assert!(row.texture_bytes.is_some_and(|b| b > 0), "{}", row.name);
            let (mean, max) = (
                row.texels_per_pixel_mean.unwrap(),
                row.texels_per_pixel_max.unwrap(),
            );
            assert!(
                mean >= 1.0 && mean <= max as f64,
                "{}: mean {mean} max {max}",
                row.name
            );
        }
    }
    // Nearest reads one texel per pixel, bilinear four (the 2x2 quad).
    assert_eq!(report.rows[0].texels_per_pixel_mean, Some(1.0));
    assert_eq!(report.rows[0].texels_per_pixel_max, Some(1));
    assert_eq!(report.rows[1].texels_per_pixel_max, Some(4));
    // The extra image is copied unchanged and, being texel's bilinear image, scores as bilinear.
    let gpu = &report.rows[4];
    assert!(gpu.extra);
    assert_eq!(load(out.join(&gpu.image)), load(&extra));
    assert_eq!(load(&extra), load(out.join(&report.rows[1].image)));
    assert_eq!(
        (gpu.psnr_all, gpu.psnr_band, gpu.ssim),
        (
            report.rows[1].psnr_all,
            report.rows[1].psnr_band,
            report.rows[1].ssim
        )
    );

    // Two identical images are within the reference's noise of each other, whatever its noise.
    assert!(gpu.within_noise_of.contains(&"bilinear".to_string()));
    assert!(report.rows[1].within_noise_of.contains(&"gpu".to_string()));
    // The reference is `texel reference` with the same minimum and no refinement, bit for bit,
    // and the report says what it measured of its own error.
    let alone = d.arg("alone.png");
    ok(&[
        "reference",
        "builtin:ground",
        "--size",
        "96x54",
        "--spp",
        "16",
        "--max-spp",
        "16",
        "-o",
        &alone,
    ]);
    assert_eq!(load(&alone), reference);
    let e = report
        .reference_error
        .as_ref()
        .expect("the reference's error");
    assert_eq!(
        (e.min_spp, e.max_spp, e.mean_spp, e.block),
        (16, 16, 16.0, 8)
    );
    assert!((0.0..=1.0).contains(&e.converged), "{}", e.converged);
    // A 16-sample reference of a checkerboard is noisy: its floor is finite, and no filter
    // scores above it.
    assert!(
        e.noise_floor.is_finite() && e.noise_floor_block > e.noise_floor,
        "{e:?}"
    );
    for row in &report.rows {
        assert!(
            row.psnr_all < e.noise_floor + 3.0,
            "{}: {}",
            row.name,
            row.psnr_all
        );
    }

    // report.md has the same table; index.html shows every image.
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    for row in &report.rows {
        assert!(
            md.contains(&format!("{:.2}", row.psnr_all)),
            "report.md lacks {}'s PSNR",
            row.name
        );
        assert!(html.contains(&row.image), "index.html lacks {}", row.image);
    }
    assert!(md.contains("gpu (extra)"));
    assert!(md.contains("Noise floor"), "{md}");
    assert!(html.contains("<svg"), "no chart in index.html");
    assert!(temp_files(&out).is_empty());
}

#[test]
fn ground_plane_filter_ranking_against_a_256_sample_reference() {
    let d = Dir::new("ranking");
    let out = d.arg("report");
    ok(&[
        "compare",
        "builtin:ground",
        "--size",
        "192x108",
        "--spp",
        "256",
        "--filters",
        "nearest,bilinear,trilinear,aniso16,ewa",
        "--out",
        &out,
    ]);
    let psnr = psnr_of(&d.join("report/report.json"));
    let (n, b, t, a, e) = (
        psnr("nearest"),
        psnr("bilinear"),
        psnr("trilinear"),
        psnr("aniso16"),
        psnr("ewa"),
    );
    assert!(e > t && a > t, "ewa {e} aniso16 {a} trilinear {t}");
    assert!(t > b, "trilinear {t} bilinear {b}");
    assert!(b > n, "bilinear {b} nearest {n}");
    // The reference's error bars support each of those rankings.
    let report =
        Report::from_json(&std::fs::read_to_string(d.join("report/report.json")).unwrap()).unwrap();
    let tied = |x: &str, y: &str| {
        let row = report.rows.iter().find(|r| r.name == x).unwrap();
        row.within_noise_of.iter().any(|o| o == y)
    };
    for (x, y) in [
        ("ewa", "trilinear"),
        ("aniso16", "trilinear"),
        ("trilinear", "bilinear"),
        ("bilinear", "nearest"),
    ] {
        assert!(!tied(x, y), "{x} and {y} are within the reference's noise");
    }
}

#[test]
fn footprint_aware_environment_lookups_beat_level_zero_on_the_rippled_mirror() {
    // The same sky laid out in each mapping: every one filters its reflections by footprint.
    for mapping in ["equirect", "cube", "octahedral"] {
        let d = Dir::new(&format!("mirror-plane-{mapping}"));
        let out = d.arg("report");
        ok(&[
            "compare",
            "builtin:mirror-plane",
            "--environment-mapping",
            mapping,
            "--size",
            "320x180",
            "--spp",
            "64",
            "--filters",
            "bilinear,trilinear,aniso16,ewa",
            "--out",
            &out,
        ]);
        let psnr = psnr_of(&d.join("report/report.json"));
        let (b, t, a, e) = (
            psnr("bilinear"),
            psnr("trilinear"),
            psnr("aniso16"),
            psnr("ewa"),
        );
        // Every filter reads the reflection through its own footprint; bilinear reads level 0.
        assert!(t > b + 2.0, "{mapping}: trilinear {t} bilinear {b}");
        assert!(
            a > t && e > t,
            "{mapping}: aniso16 {a} ewa {e} trilinear {t}"
        );
    }
}

#[test]
fn per_pixel_sphere_mappings_beat_per_vertex_against_the_reference() {
    // The reference evaluates each globe's projection at every sample; interpolating the
    // vertices' uv misplaces the map between the 5.6-degree rings, most where Mercator's v
    // bends hardest (towards its cut).
    for (scene, margin) in [("globe", 1.0), ("globe-equirect", 0.3)] {
        let at = |surface: &str| {
            let d = Dir::new(&format!("{scene}-{surface}"));
            ok(&[
                "compare",
                &format!("builtin:{scene}"),
                "--surface-uv",
                surface,
                "--size",
                "640x360",
                "--spp",
                "36",
                "--filters",
                "aniso16",
                "--out",
                &d.arg("report"),
            ]);
            psnr_of(&d.join("report/report.json"))("aniso16")
        };
        let (pixel, vertex) = (at("pixel"), at("vertex"));
        assert!(
            pixel > vertex + margin,
            "{scene}: per pixel {pixel} dB, per vertex {vertex} dB"
        );
    }
}

#[test]
fn only_the_procedural_sky_is_laid_out_anew() {
    let d = Dir::new("env-file-mapping");
    let mut hdr = Vec::new();
    let pixels = vec![image::Rgb([1.0f32, 0.5, 0.25]); 8 * 4];
    image::codecs::hdr::HdrEncoder::new(&mut hdr)
        .encode(&pixels, 8, 4)
        .unwrap();
    d.write("sky.hdr", &hdr);
    let scene = d.write(
        "scene.toml",
        format!("{HEAD}{TRIANGLE}\n[environment]\npath = \"sky.hdr\"\n"),
    );
    let out = d.arg("a.png");
    let scene = scene.to_str().unwrap();
    ok(&["render", scene, "-o", &out]);
    ok(&[
        "render",
        scene,
        "--environment-mapping",
        "equirect",
        "-o",
        &out,
    ]);
    fails(
        &["render", scene, "--environment-mapping", "cube", "-o", &out],
        1,
        &["only the procedural sky", "equirect"],
    );
}

/// The whole-image PSNR of each row of the report at `path`, by filter name.
fn psnr_of(path: &std::path::Path) -> impl Fn(&str) -> f64 {
    let report = Report::from_json(&std::fs::read_to_string(path).unwrap()).unwrap();
    move |name| {
        report
            .rows
            .iter()
            .find(|r| r.name == name)
            .unwrap()
            .psnr_all
    }
}

/// A report says when its frames were filtered with `--precision gpu`, and not otherwise.
#[test]
fn compare_reports_gpu_precision() {
    let d = Dir::new("compare-precision");
    for (precision, said) in [("gpu", true), ("exact", false)] {
        let out = d.arg(precision);
        let args = ["compare", "--color", "raw", "--size", "64x36", "--spp", "4"];
        let more = [
            "--filters",
            "bilinear",
            "--precision",
            precision,
            "--out",
            &out,
        ];
        ok(&[&args[..], &more[..]].concat());
        let md = std::fs::read_to_string(d.join(precision).join("report.md")).unwrap();
        assert_eq!(md.contains("colour raw, gpu precision."), said, "{md}");
        assert!(md.contains("colour raw"), "{md}");
    }
}
