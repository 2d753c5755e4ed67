//! The filter report: one row per filter (and per external image), as JSON and Markdown.
//! The HTML page is in [`crate::html`].
//!
//! JSON numbers: PSNR is `+inf` for an image identical to the reference, which JSON cannot hold;
//! it is written as the string `"inf"` (and read back from it). Rows for external images
//! (`--extra LABEL=IMAGE`) have no timing, texel or memory numbers: those fields are `null`.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::QualityError;
use crate::scores::Scores;
use texel_io::write_atomic;

/// A whole report: the scene, its settings and one row per filter or external image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Report {
    /// Scene name or path as the user gave it (e.g. `builtin:ground`).
    pub scene: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel of the reference.
    pub spp: u32,
    /// Colour handling: `"srgb"` or `"raw"`.
    pub color: String,
    /// File name of the reference image, relative to the report's directory.
    pub reference_image: String,
    /// File name of the reference's enlarged horizon crop, if any.
    #[serde(default)]
    pub reference_crop: Option<String>,
    /// Depth of the horizon band in rows ([`crate::horizon_band`]).
    pub band_rows: u32,
    /// Error (8-bit units) at the top of the heat maps' colour ramp.
    pub heat_map_max: f32,
    /// One row per filter, then the external images.
    pub rows: Vec<FilterRow>,
    /// The camera orbit the rows' flicker and orbit PSNR were measured over (`--orbit`).
    #[serde(default)]
    pub orbit: Option<Orbit>,
    /// How sure the reference is, where it measured its own error.
    #[serde(default)]
    pub reference_error: Option<ReferenceSummary>,
}

/// The reference's own uncertainty ([`crate::ReferenceError`]), over the covered pixels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSummary {
    /// Samples every pixel got.
    pub min_spp: u32,
    /// The most samples a pixel could get.
    pub max_spp: u32,
    /// Mean samples per covered pixel.
    pub mean_spp: f64,
    /// Half-width of a converged pixel's 95 % interval, in 8-bit steps of the display.
    pub tolerance: f64,
    /// Share of the covered pixels that met the tolerance.
    pub converged: f64,
    /// Share of the covered pixels whose integral was computed, not sampled (exact to the
    /// arithmetic: standard error 0).
    #[serde(default)]
    pub exact: f64,
    /// PSNR (dB) a perfect filter would score against this reference per pixel: no score above
    /// it means anything.
    #[serde(with = "inf_f64")]
    pub noise_floor: f64,
    /// The same for the block-mean PSNR.
    #[serde(with = "inf_f64")]
    pub noise_floor_block: f64,
    /// Side of the blocks of the block-mean PSNR, in pixels.
    pub block: u32,
}

/// A slow camera orbit (`texel compare --orbit N`): the scene's camera turned about its up axis
/// through the target by `step_deg` per frame, `frames` frames from the scene's own view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Orbit {
    /// Frames, the scene's own view first.
    pub frames: u32,
    /// Degrees turned per frame.
    pub step_deg: f32,
    /// The reference's own frame-to-frame change ([`crate::mean_abs_change`] between consecutive
    /// frames, averaged): the change that motion causes, which the rows' flicker figures exclude
    /// pixel by pixel.
    pub reference_flicker: f64,
}

/// One filter's (or one external image's) results.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilterRow {
    /// Filter name (`trilinear`, `aniso16`, ...) or the external image's label.
    pub name: String,
    /// `true` for an image rendered elsewhere (`--extra`).
    #[serde(default)]
    pub extra: bool,
    /// PSNR in dB over the covered pixels (`"inf"` in JSON when identical).
    #[serde(with = "inf_f64")]
    pub psnr_all: f64,
    /// PSNR in dB over the horizon band.
    #[serde(with = "inf_f64")]
    pub psnr_band: f64,
    /// Mean SSIM over the covered pixels.
    pub ssim: f64,
    /// Texels read per covered pixel, mean. `None` for external images.
    pub texels_per_pixel_mean: Option<f64>,
    /// Texels read per pixel, maximum. `None` for external images.
    pub texels_per_pixel_max: Option<u64>,
    /// Milliseconds per frame (median). `None` for external images.
    pub ms_per_frame: Option<f64>,
    /// Bytes of the texture structures the filter needs (pyramid, ripmap, SAT). `None` for
    /// external images.
    pub texture_bytes: Option<u64>,
    /// The image's file name, relative to the report's directory.
    pub image: String,
    /// The error heat map's file name.
    #[serde(default)]
    pub heat_map: Option<String>,
    /// The enlarged horizon crop's file name.
    #[serde(default)]
    pub horizon_crop: Option<String>,
    /// With an orbit: the frame-to-frame change less the reference's, per pixel, as a mean
    /// absolute value in 8-bit units ([`crate::excess_change`]), averaged over the orbit's
    /// consecutive pairs ([`Orbit`]). 0: it changes exactly as the reference does.
    #[serde(default)]
    pub flicker: Option<f64>,
    /// With an orbit: PSNR over the covered pixels averaged over the orbit's frames.
    #[serde(default)]
    pub psnr_orbit: Option<f64>,
    /// PSNR in dB on block means in linear light ([`crate::block_psnr`], blocks of
    /// [`ReferenceSummary::block`]); `"inf"` in JSON when equal.
    #[serde(default, with = "opt_inf_f64")]
    pub psnr_block: Option<f64>,
    /// The other rows whose per-pixel PSNR difference from this one lies within the reference's
    /// 95 % uncertainty ([`crate::MseDifference::distinguishable`]): the reference does not rank
    /// them against this one.
    #[serde(default)]
    pub within_noise_of: Vec<String>,
}

impl FilterRow {
    /// The row's time per frame where it has one that can be compared: positive and finite.
    pub fn time(&self) -> Option<f64> {
        self.ms_per_frame.filter(|ms| *ms > 0.0 && ms.is_finite())
    }

    /// A row with `scores` and file name `image`, no timing/texel/memory numbers and no extra
    /// images; set the other fields directly.
    pub fn new(name: impl Into<String>, scores: Scores, image: impl Into<String>) -> Self {
        FilterRow {
            name: name.into(),
            extra: false,
            psnr_all: scores.psnr_all,
            psnr_band: scores.psnr_band,
            ssim: scores.ssim,
            texels_per_pixel_mean: None,
            texels_per_pixel_max: None,
            ms_per_frame: None,
            texture_bytes: None,
            image: image.into(),
            heat_map: None,
            horizon_crop: None,
            flicker: None,
            psnr_orbit: None,
            psnr_block: None,
            within_noise_of: Vec::new(),
        }
    }
}

/// `f64` with `+inf`/`-inf` as the strings `"inf"`/`"-inf"` (JSON has no infinities).
mod inf_f64 {
    use serde::{Deserialize, Deserializer, Serializer};

    pub(super) fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if *v == f64::INFINITY {
            s.serialize_str("inf")
        } else if *v == f64::NEG_INFINITY {
            s.serialize_str("-inf")
        } else {
            s.serialize_f64(*v)
        }
    }

    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Repr {
        Num(f64),
        Str(String),
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        match Repr::deserialize(d)? {
            Repr::Num(v) => Ok(v),
            Repr::Str(s) if s == "inf" => Ok(f64::INFINITY),
            Repr::Str(s) if s == "-inf" => Ok(f64::NEG_INFINITY),
            Repr::Str(s) => Err(serde::de::Error::custom(format!(
                "expected a number, \"inf\" or \"-inf\", got {s:?}"
            ))),
        }
    }
}

/// `Option<f64>` with infinities as in [`inf_f64`] and `None` as `null`.
mod opt_inf_f64 {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize)]
    struct Ser(#[serde(with = "super::inf_f64")] f64);

    #[derive(Deserialize)]
    struct De(#[serde(with = "super::inf_f64")] f64);

    pub(super) fn serialize<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        v.map(Ser).serialize(s)
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        Ok(Option::<De>::deserialize(d)?.map(|De(v)| v))
    }
}

/// A PSNR for a table: two decimals, `inf` for identical.
pub(crate) fn fmt_psnr(v: f64) -> String {
    if v.is_infinite() {
        if v > 0.0 { "inf" } else { "-inf" }.to_string()
    } else {
        format!("{v:.2}")
    }
}

/// An optional number for a table (`-` when absent).
pub(crate) fn fmt_opt<T>(v: Option<T>, f: impl Fn(T) -> String) -> String {
    v.map_or_else(|| "-".to_string(), f)
}

/// The table's cells for one row, in [`table_header`] order (with the orbit's columns when
/// `orbit`).
pub(crate) fn row_cells(r: &FilterRow, orbit: bool) -> Vec<String> {
    let mut cells = vec![
        if r.extra {
            format!("{} (extra)", r.name)
        } else {
            r.name.clone()
        },
        fmt_psnr(r.psnr_all),
        fmt_psnr(r.psnr_band),
        fmt_opt(r.psnr_block, fmt_psnr),
        format!("{:.4}", r.ssim),
        fmt_opt(r.texels_per_pixel_mean, |v| format!("{v:.1}")),
        fmt_opt(r.texels_per_pixel_max, |v| v.to_string()),
        fmt_opt(r.ms_per_frame, |v| format!("{v:.2}")),
        fmt_opt(r.texture_bytes, |v| v.to_string()),
        if r.within_noise_of.is_empty() {
            "-".to_string()
        } else {
            r.within_noise_of.join(", ")
        },
    ];
    if orbit {
        cells.push(fmt_opt(r.psnr_orbit, fmt_psnr));
        cells.push(fmt_opt(r.flicker, |v| format!("{v:.2}")));
    }
    cells
}

/// Column headers of the report table, with the orbit's when `orbit`.
pub(crate) fn table_header(orbit: bool) -> Vec<&'static str> {
    let mut h = TABLE_HEADER.to_vec();
    if orbit {
        h.extend(["PSNR orbit (dB)", "flicker"]);
    }
    h
}

/// Column headers of the report table without an orbit.
const TABLE_HEADER: [&str; 10] = [
    "filter",
    "PSNR all (dB)",
    "PSNR band (dB)",
    "PSNR blocks (dB)",
    "SSIM",
    "texels/px mean",
    "texels/px max",
    "ms/frame",
    "texture bytes",
    "within noise of",
];

/// Escape a Markdown table cell (`|`, `\`, newlines).
fn md_cell(s: &str) -> String {
    s.replace('\\', "\\\\")
        .replace('|', "\\|")
        .replace(['\n', '\r'], " ")
}

impl ReferenceSummary {
    /// One paragraph: the samples, the share converged, the noise floors and what the "within
    /// noise of" column means.
    pub fn sentence(&self) -> String {
        let tail = format!(
            "Noise floor (the PSNR a perfect filter would score against this reference): {} dB \
             per pixel, {} dB on {b}x{b} block means in linear light (PSNR blocks). \"Within noise \
             of\" lists the rows whose PSNR difference from the row lies within the reference's 95 % \
             uncertainty: the reference does not rank them.",
            fmt_psnr(self.noise_floor),
            fmt_psnr(self.noise_floor_block),
            b = self.block,
        );
        if self.exact >= 1.0 {
            return format!(
                "Reference: every covered pixel exact (its integral computed, to within 1e-6 of \
                 the value). {tail}"
            );
        }
        let exact = if self.exact > 0.0 {
            format!(
                "{:.1} % of the covered pixels exact (their integral computed, to within 1e-6 of \
                 the value), the others sampled: ",
                100.0 * self.exact
            )
        } else {
            String::new()
        };
        format!(
            "Reference: {exact}{}-{} samples per pixel (mean {:.0}); {:.1} % of the covered pixels \
             within ±{}/255 of the display at 95 % confidence. {tail}",
            self.min_spp,
            self.max_spp,
            self.mean_spp,
            100.0 * self.converged,
            self.tolerance,
        )
    }
}

impl Report {
    /// Pretty-printed JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a report always serialises") + "\n"
    }

    /// Parse JSON written by [`Report::to_json`].
    ///
    /// # Errors
    /// [`QualityError::Json`] for malformed JSON, unknown fields or missing ones.
    pub fn from_json(s: &str) -> Result<Report, QualityError> {
        Ok(serde_json::from_str(s)?)
    }

    /// Indices into `rows` of the frontier of quality against time, fastest first: the timed rows
    /// (a positive, finite ms per frame and a PSNR over the covered pixels that is not NaN) that no
    /// other timed row beats on both axes, as fast or faster and at least as good, better in one.
    /// Rows equal on both axes are on it together.
    pub fn frontier(&self) -> Vec<usize> {
        let mut timed: Vec<(usize, f64, f64)> = self
            .rows
            .iter()
            .enumerate()
            .filter(|(_, r)| !r.psnr_all.is_nan())
            .filter_map(|(i, r)| Some((i, r.time()?, r.psnr_all)))
            .collect();
        // Fastest first, and within one time the best first.
        timed.sort_by(|a, b| a.1.total_cmp(&b.1).then(b.2.total_cmp(&a.2)));
        let mut out = Vec::new();
        // The best PSNR of the strictly faster rows.
        let mut best = f64::NEG_INFINITY;
        let mut k = 0;
        while k < timed.len() {
            let ms = timed[k].1;
            let top = timed[k].2;
            let group = timed[k..].iter().take_while(|t| t.1 == ms).count();
            if top > best {
                out.extend(
                    timed[k..k + group]
                        .iter()
                        .filter(|t| t.2 == top)
                        .map(|t| t.0),
                );
            }
            best = best.max(top);
            k += group;
        }
        out
    }

    /// The Markdown table (GitHub flavour) with a one-paragraph header.
    pub fn to_markdown(&self) -> String {
        let mut s = format!(
            "# texel filter report: {}\n\n{}x{} pixels, reference {} samples per pixel, colour {}. \
             PSNR and SSIM against the reference over the covered pixels; the band is the {} rows \
             below the horizon. Rows marked (extra) were rendered elsewhere (an --extra image, or \
             --gpu: gpu-NAME by texel's shaders, hw-NAME by the device's sampler, ms/frame on the \
             device): no texel or memory numbers.\n\n",
            md_cell(&self.scene),
            self.width,
            self.height,
            self.spp,
            md_cell(&self.color),
            self.band_rows
        );
        if let Some(e) = &self.reference_error {
            s += &e.sentence();
            s += "\n\n";
        }
        let orbit = self.orbit.is_some();
        if let Some(o) = &self.orbit {
            s += &format!(
                "Orbit: {} frames, {} degrees per frame about the camera's up axis through its \
                 target. PSNR orbit is the mean over the frames; flicker is the change between \
                 consecutive frames less the reference's change, pixel by pixel, as a mean absolute \
                 value (8-bit units; the reference's own change is {:.2}).\n\n",
                o.frames, o.step_deg, o.reference_flicker
            );
        }
        let header = table_header(orbit);
        s += &format!("| {} |\n", header.join(" | "));
        s += &format!("|---{}|\n", "|--:".repeat(header.len() - 1));
        for r in &self.rows {
            let cells: Vec<String> = row_cells(r, orbit).iter().map(|c| md_cell(c)).collect();
            s += &format!("| {} |\n", cells.join(" | "));
        }
        let frontier = self.frontier();
        if !frontier.is_empty() {
            let names: Vec<String> = frontier
                .iter()
                .map(|&i| md_cell(&self.rows[i].name))
                .collect();
            s += &format!(
                "\nThe frontier of quality against time (the rows no other row beats on both PSNR \
                 all and ms/frame), fastest first: {}.\n",
                names.join(", ")
            );
        }
        s
    }

    /// Write `report.json`, `report.md` and `index.html` into `dir` (which must exist), each
    /// atomically.
    ///
    /// # Errors
    /// As [`write_atomic`].
    pub fn write(&self, dir: &Path) -> Result<(), QualityError> {
        write_atomic(&dir.join("report.json"), self.to_json().as_bytes())?;
        write_atomic(&dir.join("report.md"), self.to_markdown().as_bytes())?;
        Ok(write_atomic(
            &dir.join("index.html"),
            self.to_html().as_bytes(),
        )?)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The frontier against its definition, pair by pair, on random rows with ties in time and
    /// in PSNR, untimed rows and infinite PSNR.
    #[test]
    fn frontier_is_the_undominated_timed_rows() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % n
        };
        for _ in 0..500 {
            let mut report = sample();
            let n = 1 + next(9) as usize;
            report.rows = (0..n)
                .map(|k| {
                    let mut r = report.rows[0].clone();
                    r.name = format!("r{k}");
                    r.ms_per_frame = match next(6) {
                        0 => None,
                        _ => Some(1.0 + next(4) as f64),
                    };
                    r.psnr_all = match next(8) {
                        0 => f64::INFINITY,
                        _ => 10.0 + next(4) as f64,
                    };
                    r
                })
                .collect();
            let timed = |r: &FilterRow| r.ms_per_frame.is_some();
            let beats = |a: &FilterRow, b: &FilterRow| {
                let (ta, tb) = (a.ms_per_frame.unwrap(), b.ms_per_frame.unwrap());
                ta <= tb && a.psnr_all >= b.psnr_all && (ta < tb || a.psnr_all > b.psnr_all)
            };
            let want: Vec<usize> = (0..n)
                .filter(|&i| {
                    let r = &report.rows[i];
                    timed(r) && !report.rows.iter().any(|o| timed(o) && beats(o, r))
                })
                .collect();
            let mut got = report.frontier();
            // Fastest first.
            let ms: Vec<f64> = got
                .iter()
                .map(|&i| report.rows[i].ms_per_frame.unwrap())
                .collect();
            assert!(ms.windows(2).all(|w| w[0] <= w[1]), "{ms:?}");
            got.sort_unstable();
            assert_eq!(got, want);
        }
    }

    pub(crate) fn sample() -> Report {
        let mut tri = FilterRow::new(
            "trilinear",
            Scores {
                psnr_all: 27.5,
                psnr_band: 19.25,
                ssim: 0.91,
            },
            "trilinear.png",
        );
        tri.texels_per_pixel_mean = Some(8.0);
        tri.texels_per_pixel_max = Some(8);
        tri.ms_per_frame = Some(12.5);
        tri.texture_bytes = Some(5_592_404);
        tri.heat_map = Some("trilinear_error.png".into());
        tri.horizon_crop = Some("trilinear_crop.png".into());
        let mut near = tri.clone();
        near.name = "nearest".into();
        near.psnr_all = 14.0;
        near.ms_per_frame = Some(3.0);
        let mut same = tri.clone();
        same.name = "self".into();
        same.psnr_all = f64::INFINITY;
        same.psnr_band = f64::INFINITY;
        let mut extra = FilterRow::new(
            "gpu <a|b>",
            Scores {
                psnr_all: 21.3,
                psnr_band: 15.0,
                ssim: 0.8,
            },
            "extra_gpu.png",
        );
        extra.extra = true;
        Report {
            scene: "builtin:ground".into(),
            width: 320,
            height: 180,
            spp: 256,
            color: "srgb".into(),
            reference_image: "reference.png".into(),
            reference_crop: Some("reference_crop.png".into()),
            band_rows: 18,
            heat_map_max: 32.0,
            rows: vec![near, tri, same, extra],
            orbit: None,
            reference_error: None,
        }
    }

    #[test]
    fn an_orbit_adds_its_columns_and_round_trips() {
        let mut r = sample();
        assert!(!r.to_markdown().contains("flicker"));
        r.orbit = Some(Orbit {
            frames: 8,
            step_deg: 0.1,
            reference_flicker: 1.25,
        });
        r.rows[0].flicker = Some(3.5);
        r.rows[0].psnr_orbit = Some(14.25);
        let md = r.to_markdown();
        assert!(md.contains("| PSNR orbit (dB) | flicker |"), "{md}");
        assert!(md.contains("| 14.25 | 3.50 |"), "{md}");
        assert!(md.contains("the reference's own change is 1.25"), "{md}");
        // Rows without the figures (extras) show dashes; every row has the header's cell count.
        let header_cells = md
            .lines()
            .find(|l| l.starts_with("| filter"))
            .unwrap()
            .matches('|')
            .count();
        for line in md.lines().filter(|l| l.starts_with("| ")) {
            assert_eq!(
                line.matches('|').count() - line.matches("\\|").count(),
                header_cells,
                "{line}"
            );
        }
        assert!(r.to_html().contains("<th>flicker</th>"));
        assert_eq!(Report::from_json(&r.to_json()).unwrap(), r);
    }

    #[test]
    fn json_round_trip_with_inf_and_nulls() {
        let r = sample();
        let j = r.to_json();
        assert!(j.contains("\"psnr_all\": \"inf\""), "{j}");
        assert!(j.contains("\"ms_per_frame\": null"));
        assert_eq!(Report::from_json(&j).unwrap(), r);
        let v: serde_json::Value = serde_json::from_str(&j).unwrap();
        assert_eq!(v["rows"][1]["psnr_all"], 27.5);
        assert_eq!(v["rows"][3]["extra"], true);
    }

    #[test]
    fn json_errors() {
        let j = sample().to_json().replace("\"spp\"", "\"spp_typo\"");
        assert!(matches!(Report::from_json(&j), Err(QualityError::Json(_))));
        let j = sample().to_json().replacen("\"inf\"", "\"big\"", 1);
        assert!(Report::from_json(&j).is_err());
    }

    #[test]
    fn markdown_table() {
        let md = sample().to_markdown();
        let lines: Vec<&str> = md.lines().filter(|l| l.starts_with('|')).collect();
        assert_eq!(lines.len(), 2 + 4);
        assert_eq!(
            lines[3],
            "| trilinear | 27.50 | 19.25 | - | 0.9100 | 8.0 | 8 | 12.50 | 5592404 | - |"
        );
        assert!(lines[4].starts_with("| self | inf | inf |"));
        assert_eq!(
            lines[5],
            "| gpu <a\\|b> (extra) | 21.30 | 15.00 | - | 0.8000 | - | - | - | - | - |"
        );
        // Every row has the header's number of cells (escaped pipes do not split).
        for l in &lines {
            assert_eq!(l.replace("\\|", "").matches('|').count(), 11, "{l}");
        }
    }

    #[test]
    fn the_reference_error_and_block_scores_round_trip() {
        let mut r = sample();
        r.reference_error = Some(ReferenceSummary {
            min_spp: 256,
            max_spp: 4096,
            mean_spp: 700.4,
            tolerance: 0.5,
            converged: 0.9625,
            exact: 0.0,
            noise_floor: 41.234,
            noise_floor_block: f64::INFINITY,
            block: 8,
        });
        r.rows[1].psnr_block = Some(33.125);
        r.rows[2].psnr_block = Some(f64::INFINITY);
        r.rows[1].within_noise_of = vec!["self".into(), "nearest".into()];
        let md = r.to_markdown();
        assert!(md.contains("256-4096 samples per pixel (mean 700)"), "{md}");
        assert!(
            md.contains("96.2 % of the covered pixels within ±0.5/255"),
            "{md}"
        );
        assert!(
            md.contains("41.23 dB per pixel, inf dB on 8x8 block means"),
            "{md}"
        );
        assert!(
            md.contains("| trilinear | 27.50 | 19.25 | 33.12 | 0.9100 | 8.0 | 8 | 12.50 | 5592404 | self, nearest |"),
            "{md}"
        );
        assert!(r.to_html().contains("<td>self, nearest</td>"));
        let j = r.to_json();
        assert!(j.contains("\"psnr_block\": \"inf\""), "{j}");
        assert!(j.contains("\"psnr_block\": null"), "{j}");
        assert_eq!(Report::from_json(&j).unwrap(), r);
        // Reports without the new fields still read.
        let v: serde_json::Value = serde_json::from_str(&sample().to_json()).unwrap();
        let mut old = v.clone();
        for row in old["rows"].as_array_mut().unwrap() {
            let row = row.as_object_mut().unwrap();
            row.remove("psnr_block");
            row.remove("within_noise_of");
        }
        old.as_object_mut().unwrap().remove("reference_error");
        assert_eq!(Report::from_json(&old.to_string()).unwrap(), sample());
        // An exact reference says so: in part, then wholly.
        let mut e = r.reference_error.clone().unwrap();
        e.exact = 0.25;
        let text = e.sentence();
        assert!(
            text.contains("25.0 % of the covered pixels exact"),
            "{text}"
        );
        assert!(
            text.contains("the others sampled: 256-4096 samples"),
            "{text}"
        );
        e.exact = 1.0;
        let text = e.sentence();
        assert!(
            text.starts_with("Reference: every covered pixel exact"),
            "{text}"
        );
        assert!(!text.contains("samples per pixel"), "{text}");
    }
}
