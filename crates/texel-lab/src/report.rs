//! `texel lab`'s report: `report.json` (every figure), `report.md` and `report.html` (the same
//! tables with the images), written atomically into the report folder.

use std::fmt::Write as _;
use std::path::Path;

use crate::{Error, Images, LabReport, Verdict};

fn verdict_name(v: Verdict) -> &'static str {
    match v {
        Verdict::Gl => "gl",
        Verdict::Lab => "lab",
        Verdict::Neither => "neither",
    }
}

fn pct(x: f64) -> String {
    format!("{:.1} %", 100.0 * x)
}

fn db(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.1}")
    } else {
        "inf".into()
    }
}

const MODE_NAMES: [&str; 8] = [
    "nearest",
    "bilinear",
    "bilinear, nearest mip level",
    "trilinear",
    "anisotropic 2x",
    "anisotropic 4x",
    "anisotropic 8x",
    "anisotropic 16x",
];

fn mode_name(m: u8) -> &'static str {
    MODE_NAMES
        .get(usize::from(m).wrapping_sub(1))
        .copied()
        .unwrap_or("?")
}

/// The report as Markdown (`html`: as the body of an HTML page, images inline).
pub fn markdown(r: &LabReport) -> String {
    let mut s = String::new();
    head(&mut s, r);
    modes(&mut s, r);
    questions(&mut s, r);
    s
}

/// The title, the score by the rubric's parts, the texture rule and the comments.
fn head(s: &mut String, r: &LabReport) {
    let _ = writeln!(s, "# texel lab: {}\n", r.shader);
    let _ = writeln!(s, "Device: {} ({}).\n", r.renderer, r.gl_version);
    let _ = writeln!(s, "**Score: {:.1} / 100**\n", r.score);
    let _ = writeln!(s, "| part | weight | modes | earned |\n|---|---|---|---|");
    for p in &r.rubric {
        let modes: Vec<String> = p.modes.iter().map(u8::to_string).collect();
        let _ = writeln!(
            s,
            "| {} | {} % | {} | {:.1} |",
            p.part,
            p.weight,
            modes.join(", "),
            p.earned
        );
    }
    let _ = writeln!(s, "\n## The rule: texelFetch and textureSize only\n");
    if r.rule_violations.is_empty() {
        let _ = writeln!(s, "No other texture built-in is used.");
    } else {
        let _ = writeln!(
            s,
            "**The shader breaks the rule** (it is still rendered and graded):\n"
        );
        for v in &r.rule_violations {
            let _ = writeln!(s, "- line {}: `{}`", v.line, v.call);
        }
    }
    if !r.level_size_queries.is_empty() {
        let lines: Vec<String> = r.level_size_queries.iter().map(usize::to_string).collect();
        let _ = writeln!(
            s,
            "\nNote: line(s) {} ask textureSize for a per-pixel level. Mesa's llvmpipe answers one size for a whole quad of pixels \
             whatever their levels, so such a shader reads wrong texels along level boundaries there (a correct one elsewhere); \
             max(textureSize(texSlot, 0) >> level, ivec2(1)) is the same size on every driver.",
            lines.join(", ")
        );
    }
    let (c, code) = r.comment_lines;
    let _ = writeln!(s, "\nComments: {c} of the shader's {code} lines of code carry one (the lab asks for comments and documentation).");
}

/// Each mode's verdict and scores, and the diagnosis of the modes that match neither convention.
fn modes(s: &mut String, r: &LabReport) {
    let (k, share) = r.agreement_measure;
    let _ = writeln!(
        s,
        "\n## The modes\n\nA mode agrees with a convention when at least {} of the covered pixels lie within {k} codes \
         (R, G and B) of texel's mode under it, evaluated on the coordinates and derivatives the device gave the shader. \
         `gl`: the OpenGL / Vulkan rules; `lab`: the handout's formulas. PSNR is against a {}-sample supersampled reference.\n",
        pct(share),
        r.reference_spp
    );
    let _ = writeln!(s, "| scene | mode | verdict | agree gl | agree lab | PSNR shader | PSNR texel | texels/pixel | GL ms |\n|---|---|---|---|---|---|---|---|---|");
    for m in &r.modes {
        let _ = writeln!(
            s,
            "| {} | {} {} | **{}** | {} | {} | {} | {} | {:.1} | {:.2} |",
            m.scene,
            m.mode,
            mode_name(m.mode),
            verdict_name(m.verdict),
            pct(m.agreement_gl),
            pct(m.agreement_lab),
            db(m.psnr_reference),
            db(m.psnr_reference_texel),
            m.texels_per_pixel,
            m.time_ms
        );
    }
    let wrong: Vec<_> = r.modes.iter().filter(|m| !m.diagnosis.is_empty()).collect();
    if !wrong.is_empty() {
        let _ = writeln!(s, "\n## Diagnosis\n");
        for m in wrong {
            let _ = writeln!(
                s,
                "- **{} mode {} ({})**:",
                m.scene,
                m.mode,
                mode_name(m.mode)
            );
            for d in &m.diagnosis {
                let _ = writeln!(s, "  - {d}");
            }
        }
    }
}

/// The lab's questions answered from the measurements.
fn questions(s: &mut String, r: &LabReport) {
    let _ = writeln!(s, "\n## The lab's questions, measured\n");
    let _ = writeln!(s, "**Magnification and minification.** Mean PSNR (dB) of the shader's modes on the magnified pixels (N < 0) and on the minified ones:\n");
    let _ = writeln!(s, "| mode | magnified | minified |\n|---|---|---|");
    for (m, a, b) in &r.questions.magnification {
        let _ = writeln!(s, "| {m} {} | {} | {} |", mode_name(*m), db(*a), db(*b));
    }
    let _ = writeln!(s, "\nNearest and bilinear read level 0 only: they serve magnification, and alias when minified. The mip modes and the anisotropic ones serve minification; when magnified they are bilinear.\n");
    let _ = writeln!(s, "**Memory of the full pyramid.**\n\n| scene | texture | grey level 0 | grey pyramid | RGB level 0 | RGB pyramid | pyramid / level 0 |\n|---|---|---|---|---|---|---|");
    for p in &r.questions.memory {
        let ratio = p.grey_pyramid as f64 / p.grey_level0.max(1) as f64;
        let _ = writeln!(
            s,
            "| {} | {} x {} | {} B | {} B | {} B | {} B | {ratio:.4} |",
            p.scene, p.size.0, p.size.1, p.grey_level0, p.grey_pyramid, p.rgb_level0, p.rgb_pyramid
        );
    }
    let _ = writeln!(
        s,
        "\nThe levels add a third of level 0 (1/4 + 1/16 + ... -> 1/3) whatever the channels.\n"
    );
    let _ = writeln!(s, "**The range of N.** N = min(M, M + log2(max(|Px|, |Py|))):\n\n| scene | M | N min | N max | N < 0 | anisotropy < 1.5 |\n|---|---|---|---|---|---|");
    for l in &r.questions.levels {
        let _ = writeln!(
            s,
            "| {} | {:.1} | {:.2} | {:.2} | {} | {} |",
            l.scene,
            l.m,
            l.n_min,
            l.n_max.min(l.m),
            pct(l.magnified),
            pct(l.isotropic)
        );
    }
    let _ = writeln!(s, "\nN runs from below 0 up to M. N < 0 means the pixel is smaller than a texel: magnification, read on level 0. Where the anisotropy is 1 the footprint is a circle: one probe, the trilinear sample at P (the handout's i / (lambda - 1) is 0 / 0 there).\n");
    let _ = writeln!(s, "**Look, time and space.** Per mode above: PSNR (look), texels read a pixel and GL milliseconds a frame (time); nearest and bilinear need level 0 alone, the others the pyramid (4/3 of it).");
}

fn html(r: &LabReport) -> String {
    let mut s = String::from("<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>texel lab</title>\n<style>body{font-family:sans-serif;max-width:1200px;margin:auto}table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 6px}img{image-rendering:pixelated;width:240px}.neither{color:#b00}</style></head><body>\n");
    let esc = |t: &str| {
        t.replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;")
    };
    let _ = writeln!(
        s,
        "<h1>texel lab: {}</h1><p>Device: {} ({})</p><h2>Score: {:.1} / 100</h2>",
        esc(&r.shader),
        esc(&r.renderer),
        esc(&r.gl_version),
        r.score
    );
    if !r.rule_violations.is_empty() {
        let _ = writeln!(
            s,
            "<p class=\"neither\"><b>The shader breaks the rule</b>:</p><ul>"
        );
        for v in &r.rule_violations {
            let _ = writeln!(s, "<li>line {}: <code>{}</code></li>", v.line, esc(&v.call));
        }
        let _ = writeln!(s, "</ul>");
    }
    let _ = writeln!(s, "<table><tr><th>scene</th><th>mode</th><th>verdict</th><th>agree gl</th><th>agree lab</th><th>PSNR</th><th>shader</th><th>texel</th><th>difference</th></tr>");
    for m in &r.modes {
        let class = if m.verdict == Verdict::Neither {
            " class=\"neither\""
        } else {
            ""
        };
        let diag = if m.diagnosis.is_empty() {
            String::new()
        } else {
            format!("<br><small>{}</small>", esc(&m.diagnosis.join("; ")))
        };
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{} {}</td><td{class}><b>{}</b>{diag}</td><td>{}</td><td>{}</td><td>{}</td><td><img src=\"{}\"></td><td><img src=\"{}\"></td><td><img src=\"{}\"></td></tr>",
            esc(&m.scene),
            m.mode,
            mode_name(m.mode),
            verdict_name(m.verdict),
            pct(m.agreement_gl),
            pct(m.agreement_lab),
            db(m.psnr_reference),
            esc(&m.images[0]),
            esc(&m.images[1]),
            esc(&m.images[2])
        );
    }
    let _ = writeln!(s, "</table><h2>Reference</h2>");
    for l in &r.questions.levels {
        let _ = writeln!(s, "<figure style=\"display:inline-block\"><img src=\"{}\"><figcaption>{}</figcaption></figure>", esc(&l.reference_image), esc(&l.scene));
    }
    let _ = writeln!(
        s,
        "<h2>Details</h2><pre>{}</pre></body></html>",
        esc(&markdown(r))
    );
    s
}

fn write_text(path: &Path, text: &str) -> Result<(), Error> {
    texel_io::write_atomic(path, text.as_bytes())
        .map_err(|e| Error::Io(format!("{}: {e}", path.display())))
}

impl LabReport {
    /// Write `report.json`, `report.md`, `report.html` and the images into `dir` (made if
    /// missing).
    ///
    /// # Errors
    /// [`Error::Io`], [`Error::Quality`].
    pub fn write(&self, images: &Images, dir: &Path) -> Result<(), Error> {
        write(self, images, dir)
    }
}

/// [`LabReport::write`].
fn write(report: &LabReport, images: &Images, dir: &Path) -> Result<(), Error> {
    let images_dir = dir.join("images");
    std::fs::create_dir_all(&images_dir)
        .map_err(|e| Error::Io(format!("{}: {e}", images_dir.display())))?;
    for (name, image) in images {
        image.write_png(dir.join(name))?;
    }
    let json = serde_json::to_string_pretty(report).map_err(|e| Error::Io(e.to_string()))?;
    write_text(&dir.join("report.json"), &json)?;
    write_text(&dir.join("report.md"), &markdown(report))?;
    write_text(&dir.join("report.html"), &html(report))
}
