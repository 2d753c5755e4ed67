//! `texel demo` and `texel bench`.

use texel::quality::Report;

use crate::util::*;

#[test]
fn demo_compares_every_builtin_scene_with_an_index() {
    let d = Dir::new("demo");
    let out = d.arg("demo");
    let run = ok(&["demo", "--size", "64x36", "--spp", "4", "--out", &out]);
    assert!(stdout(&run).contains("index.html"), "{}", stdout(&run));
    let index = std::fs::read_to_string(d.join("demo/index.html")).unwrap();
    for scene in BUILTINS {
        assert!(
            index.contains(&format!("href=\"{scene}/index.html\"")),
            "index.html does not link {scene}"
        );
        let dir = d.join(&format!("demo/{scene}"));
        assert!(dir.join("index.html").is_file() && dir.join("report.md").is_file());
        let report =
            Report::from_json(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
        assert_eq!(
            (report.width, report.height, report.spp),
            (64, 36, 4),
            "{scene}"
        );
        let names: Vec<&str> = report.rows.iter().map(|r| r.name.as_str()).collect();
        assert_eq!(names, FILTERS, "{scene}");
        for row in &report.rows {
            assert_eq!(load(dir.join(&row.image)).size(), (64, 36));
        }
    }
    // The spherical-mapping section: each globe per pixel (its own report) and per vertex, with
    // a level-of-detail view of each.
    assert!(index.contains("Spherical mappings"), "{index}");
    for globe in ["globe", "globe-equirect"] {
        assert!(index.contains(&format!("href=\"{globe}-per-vertex/index.html\"")));
        let report = Report::from_json(
            &std::fs::read_to_string(d.join(&format!("demo/{globe}-per-vertex/report.json")))
                .unwrap(),
        )
        .unwrap();
        let names: Vec<&str> = report.rows.iter().map(|r| r.name.as_str()).collect();
        assert_eq!(names, ["trilinear", "aniso16", "ewa"]);
        for at in ["pixel", "vertex"] {
            let lod = format!("mapping/{globe}-lod-{at}.png");
            assert!(index.contains(&format!("src=\"{lod}\"")), "{lod}");
            assert_eq!(load(d.join(&format!("demo/{lod}"))).size(), (64, 36));
        }
    }
    // The ambient occlusion page: the knot without and with its baked map, and the map (64 x 64
    // for a 64-pixel-wide demo), linked from the index.
    assert!(index.contains("Baked ambient occlusion"), "{index}");
    for img in ["plain.png", "with-ao.png", "ao-map.png"] {
        assert!(index.contains(&format!("src=\"ao/{img}\"")), "{img}");
    }
    assert_eq!(load(d.join("demo/ao/plain.png")).size(), (64, 36));
    assert_eq!(load(d.join("demo/ao/ao-map.png")).size(), (64, 64));
    // Occlusion only darkens: no pixel of the occluded render is brighter than the plain one.
    let plain = load(d.join("demo/ao/plain.png"));
    let with = load(d.join("demo/ao/with-ao.png"));
    let mut darker = 0;
    for (a, b) in plain.pixels().iter().zip(with.pixels()) {
        assert!((0..3).all(|c| b[c] <= a[c]), "{a:?} {b:?}");
        darker += usize::from(b[..3] != a[..3]);
    }
    assert!(darker > 100, "{darker}");
    assert!(temp_files(&d.join("demo")).is_empty());
}

#[test]
fn bench_json_has_the_llvmpipe_shape() {
    let run = ok(&[
        "bench",
        "--size",
        "64x36",
        "--frames",
        "3",
        "--warmup",
        "1",
        "--threads",
        "1",
        "--filters",
        "nearest,trilinear,ewa",
        "--json",
    ]);
    let v: serde_json::Value =
        serde_json::from_str(&stdout(&run)).unwrap_or_else(|e| panic!("{e}: {}", stdout(&run)));
    let obj = v.as_object().unwrap();
    let mut keys: Vec<&str> = obj.keys().map(String::as_str).collect();
    keys.sort_unstable();
    assert_eq!(
        keys,
        [
            "clear_ms",
            "cpu",
            "frames",
            "height",
            "median_ms",
            "precision",
            "renderer",
            "simd",
            "streamed",
            "streaming",
            "target",
            "texture_storage",
            "threads",
            "width"
        ]
    );
    assert_eq!(v["renderer"], "texel");
    assert_eq!(v["texture_storage"], "stored");
    assert_eq!(v["target"], "rgba8");
    assert_eq!(v["precision"], "exact");
    assert_eq!(v["streaming"], "auto");
    // A 64 x 36 frame fits every cache: drawn in place.
    assert_eq!(v["streamed"], false);
    assert!(v["cpu"].as_str().is_some_and(|c| !c.is_empty()));
    assert!(v["simd"]
        .as_str()
        .is_some_and(|s| s.contains("run-time dispatch")));
    assert_eq!(v["threads"], 1);
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(64), Some(36))
    );
    assert_eq!(v["frames"], 3);
    for key in ["median_ms", "clear_ms"] {
        let medians = v[key].as_object().unwrap();
        let mut filters: Vec<&str> = medians.keys().map(String::as_str).collect();
        filters.sort_unstable();
        assert_eq!(filters, ["ewa", "nearest", "trilinear"], "{key}");
        for (f, ms) in medians {
            assert!(
                ms.as_f64().is_some_and(|ms| ms.is_finite() && ms >= 0.0),
                "{key} {f}: {ms}"
            );
        }
    }
    // Without --json: a table with one line per filter.
    let run = ok(&[
        "bench",
        &ground_toml(),
        "--size",
        "64x36",
        "--frames",
        "1",
        "--filters",
        "bilinear,sat",
    ]);
    let text = stdout(&run);
    assert!(
        text.contains("median ms") && text.contains("\nbilinear ") && text.contains("\nsat "),
        "{text}"
    );
}

/// `--streaming always|never` forces either way of writing the frame, and the report says which
/// ran (`texel::raster::Streaming`).
#[test]
fn bench_streaming_is_reported() {
    let bench = |filter: &str, policy: &str, json: bool| {
        let json: &[&str] = if json { &["--json"] } else { &[] };
        stdout(&ok(&one_frame_bench(
            filter,
            &[&["--streaming", policy], json].concat(),
        )))
    };
    for (policy, streamed) in [("always", true), ("never", false)] {
        let v: serde_json::Value = serde_json::from_str(&bench("bilinear", policy, true)).unwrap();
        assert_eq!(v["streaming"], policy);
        assert_eq!(v["streamed"], streamed, "{policy}");
    }
    let text = bench("nearest", "always", false);
    assert!(text.contains("streaming: always (streamed)"), "{text}");
}

/// The report names how the textures were kept: `--texture-storage float` says `float`, and a
/// budget too small for the float copy keeps the texture stored and says so.
#[test]
fn bench_reports_texture_storage() {
    let bench = |more: &[&str]| {
        let o = texel(&one_frame_bench("aniso16", more));
        assert!(o.status.success(), "{}", stderr(&o));
        (stdout(&o), stderr(&o))
    };
    let (json, _) = bench(&["--texture-storage", "float", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["texture_storage"], "float");
    // The ground's checker: 5.3 MiB stored, 21.3 MiB as float.
    let (text, note) = bench(&["--texture-storage", "float", "--max-memory", "16M"]);
    assert!(text.contains("textures: float, 1 stored"), "{text}");
    assert!(note.contains("stays 8-bit"), "{note}");
}

/// `texel bench` of one 64 x 36 frame of `filter` without warm-up, then `more`.
fn one_frame_bench<'a>(filter: &'a str, more: &[&'a str]) -> Vec<&'a str> {
    let args = [
        "bench",
        "--size",
        "64x36",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--filters",
        filter,
    ];
    [&args[..], more].concat()
}
