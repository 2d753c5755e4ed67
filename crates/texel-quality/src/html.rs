//! The report as one self-contained `index.html`: no scripts, no external styles or fonts; the
//! images are the PNG files next to it, the chart and legend are inline SVG written by hand.
//!
//! Every piece of text that comes from outside (scene name, filter names, labels, file names) goes
//! through [`escape`], so a label like `<b>` is shown, never interpreted.
//!
//! The chart plots quality (PSNR over the covered pixels, dB, linear axis) against time
//! (ms per frame, logarithmic axis, decades with 1-2-5 ticks), one labelled point per timed filter.
//! External images have no time: each is drawn as a dashed horizontal line at its PSNR, labelled.
//! The frontier ([`Report::frontier`]: the rows no other row beats on both axes) is drawn in orange,
//! its points joined fastest first.
//! Point labels go to the first of four places around their point that overlaps no point and no earlier label.
//! Rows with infinite PSNR (identical to the reference) cannot be placed and are listed under it.

use crate::heatmap::legend_svg;
use crate::report::{fmt_psnr, row_cells, table_header, Report};

/// Escape text for HTML/SVG text and attribute values: `& < > " '`.
pub fn escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => o += "&amp;",
            '<' => o += "&lt;",
            '>' => o += "&gt;",
            '"' => o += "&quot;",
            '\'' => o += "&#39;",
            c => o.push(c),
        }
    }
    o
}

/// Chart geometry in SVG pixels.
const CW: f64 = 640.0;
const CH: f64 = 420.0;
const LEFT: f64 = 64.0;
const RIGHT: f64 = 24.0;
const TOP: f64 = 20.0;
const BOTTOM: f64 = 52.0;

/// A "nice" tick step (1, 2 or 5 times a power of ten) giving at most about 8 ticks over `span`.
fn nice_step(span: f64) -> f64 {
    let raw = (span / 8.0).max(1e-9);
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * p)
}

fn num(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// The quality-against-time scatter chart of `report` as an SVG element (module docs).
pub fn chart_svg(report: &Report) -> String {
    let frontier = report.frontier();
    let timed: Vec<(&str, f64, f64, bool)> = report
        .rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.psnr_all.is_finite())
        .filter_map(|(i, r)| {
            Some((
                r.name.as_str(),
                r.time()?,
                r.psnr_all,
                frontier.contains(&i),
            ))
        })
        .collect();
    let lines: Vec<(&str, f64)> = report
        .rows
        .iter()
        .filter(|r| r.ms_per_frame.is_none() && r.psnr_all.is_finite())
        .map(|r| (r.name.as_str(), r.psnr_all))
        .collect();
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{CW}\" height=\"{CH}\" viewBox=\"0 0 {CW} {CH}\" role=\"img\" aria-label=\"PSNR against time per filter\" font-family=\"sans-serif\" font-size=\"12\">\n"
    );
    if timed.is_empty() && lines.is_empty() {
        s += &format!(
            "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">no rows with a finite PSNR to plot</text>\n</svg>\n",
            CW / 2.0,
            CH / 2.0
        );
        return s;
    }
    let plot = Plot::new(&timed, &lines);
    s += &plot.axes();
    let line_labels = plot.dashed_lines(&lines, &mut s);
    // The frontier's points joined fastest first (the ones with a finite PSNR, which are plotted).
    let line: Vec<String> = frontier
        .iter()
        .map(|&i| &report.rows[i])
        .filter(|r| r.psnr_all.is_finite())
        .filter_map(|r| {
            Some(format!(
                "{:.1},{:.1}",
                plot.px(r.time()?),
                plot.py(r.psnr_all)
            ))
        })
        .collect();
    if line.len() > 1 {
        s += &format!(
            "<polyline points=\"{}\" fill=\"none\" stroke=\"#e67e22\" stroke-width=\"2\"/>\n",
            line.join(" ")
        );
    }
    if !line.is_empty() {
        s += &format!(
            "<text x=\"{:.1}\" y=\"{:.1}\" fill=\"#e67e22\">orange: the frontier (no other filter both faster and better)</text>\n",
            LEFT + 6.0,
            TOP + plot.ph - 8.0
        );
    }
    plot.points(&timed, &line_labels, &mut s);
    s += "</svg>\n";
    s
}

/// A label's or a point's box: left, top, right, bottom.
type LabelBox = (f64, f64, f64, f64);

/// The chart's plotting area: decades of time across, a range of PSNR up.
struct Plot {
    /// The first decade (log10 of milliseconds) across.
    dx0: f64,
    /// The last decade across.
    dx1: f64,
    /// The PSNR at the bottom.
    ya: f64,
    /// The PSNR at the top.
    yb: f64,
    /// The PSNR between ticks.
    step: f64,
    /// The plotting area's width in pixels.
    pw: f64,
    /// The plotting area's height in pixels.
    ph: f64,
}

impl Plot {
    /// The area that holds every timed point and every untimed row's line.
    fn new(timed: &[(&str, f64, f64, bool)], lines: &[(&str, f64)]) -> Plot {
        // x: decades around the timed points (one decade 1..10 ms when there are none).
        let (mut lx0, mut lx1) = timed.iter().fold((f64::MAX, f64::MIN), |(a, b), t| {
            (a.min(t.1.log10()), b.max(t.1.log10()))
        });
        if timed.is_empty() {
            (lx0, lx1) = (0.0, 1.0);
        }
        let (dx0, mut dx1) = (lx0.floor(), lx1.ceil());
        if dx1 <= dx0 {
            dx1 = dx0 + 1.0;
        }
        // y: padded range of every PSNR shown, snapped to the tick step.
        let ys = timed.iter().map(|t| t.2).chain(lines.iter().map(|l| l.1));
        let (y0, y1) = ys.fold((f64::MAX, f64::MIN), |(a, b), y| (a.min(y), b.max(y)));
        let step = nice_step((y1 - y0).max(1.0) + 2.0);
        Plot {
            dx0,
            dx1,
            ya: ((y0 - 1.0) / step).floor() * step,
            yb: ((y1 + 1.0) / step).ceil() * step,
            step,
            pw: CW - LEFT - RIGHT,
            ph: CH - TOP - BOTTOM,
        }
    }

    /// The x of a frame time.
    fn px(&self, ms: f64) -> f64 {
        LEFT + (ms.log10() - self.dx0) / (self.dx1 - self.dx0) * self.pw
    }

    /// The y of a PSNR.
    fn py(&self, db: f64) -> f64 {
        TOP + (self.yb - db) / (self.yb - self.ya) * self.ph
    }

    /// The frame, the ticks and their numbers, and the axes' titles.
    fn axes(&self) -> String {
        let (pw, ph) = (self.pw, self.ph);
        let mut s = format!(
            "<rect x=\"{LEFT}\" y=\"{TOP}\" width=\"{pw}\" height=\"{ph}\" fill=\"#fff\" stroke=\"#888\"/>\n"
        );
        // x ticks: 1, 2, 5 per decade.
        let mut d = self.dx0;
        while d <= self.dx1 + 1e-9 {
            for m in [1.0, 2.0, 5.0] {
                let ms = m * 10f64.powf(d);
                if ms.log10() > self.dx1 + 1e-9 {
                    continue;
                }
                let x = self.px(ms);
                let major = m == 1.0;
                s += &format!(
                    "<line x1=\"{x:.1}\" y1=\"{TOP}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"{}\"/>\n<text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>\n",
                    TOP + ph,
                    if major { "#ccc" } else { "#eee" },
                    TOP + ph + 16.0,
                    num(ms)
                );
            }
            d += 1.0;
        }
        // y ticks.
        let mut y = self.ya;
        while y <= self.yb + 1e-9 {
            let yy = self.py(y);
            s += &format!(
                "<line x1=\"{LEFT}\" y1=\"{yy:.1}\" x2=\"{:.1}\" y2=\"{yy:.1}\" stroke=\"#ddd\"/>\n<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>\n",
                LEFT + pw,
                LEFT - 6.0,
                yy + 4.0,
                num(y)
            );
            y += self.step;
        }
        s += &format!(
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">time per frame (ms, log scale)</text>\n<text transform=\"translate(16 {:.1}) rotate(-90)\" text-anchor=\"middle\">PSNR over the covered pixels (dB)</text>\n",
            LEFT + pw / 2.0,
            CH - 10.0,
            TOP + ph / 2.0
        );
        s
    }

    /// The untimed rows' dashed lines with their labels, drawn onto `s`; returns the labels'
    /// boxes. A label sits just above its line, at the left end, or at the right end (or
    /// staggered upwards) when an earlier line's label is in the way.
    fn dashed_lines(&self, lines: &[(&str, f64)], s: &mut String) -> Vec<LabelBox> {
        let pw = self.pw;
        let mut line_labels: Vec<LabelBox> = Vec::new();
        for (name, db) in lines {
            let yy = self.py(*db);
            let text = format!("{} ({} dB, no time)", escape(name), fmt_psnr(*db));
            let tw = 7.0
                * format!("{name} ({} dB, no time)", fmt_psnr(*db))
                    .chars()
                    .count() as f64;
            let free = |bx: f64, by: f64| {
                line_labels.iter().all(|&(x0, y0, x1, y1)| {
                    bx + tw <= x0 || bx >= x1 || by + 14.0 <= y0 || by >= y1
                })
            };
            let (left, right) = (LEFT + 6.0, LEFT + pw - 6.0 - tw);
            let (bx, by) = (0..4)
                .flat_map(|k| {
                    [
                        (left, yy - 17.0 - 14.0 * k as f64),
                        (right, yy - 17.0 - 14.0 * k as f64),
                    ]
                })
                .find(|&(bx, by)| free(bx, by))
                .unwrap_or((left, yy - 17.0));
            line_labels.push((bx, by, bx + tw, by + 14.0));
            *s += &format!(
                "<line x1=\"{LEFT}\" y1=\"{yy:.1}\" x2=\"{:.1}\" y2=\"{yy:.1}\" stroke=\"#c0392b\" stroke-dasharray=\"6 4\"/>\n<text x=\"{bx:.1}\" y=\"{:.1}\" fill=\"#c0392b\">{text}</text>\n",
                LEFT + pw,
                by + 12.0,
            );
        }
        line_labels
    }

    /// The timed rows' points and labels, drawn onto `s`. A label takes the first of four places
    /// around its point (right-above, right-below, left-above, left-below) that overlaps no point,
    /// no dashed line's label and no label placed before; text width is estimated at 7 px a
    /// character.
    fn points(&self, timed: &[(&str, f64, f64, bool)], line_labels: &[LabelBox], s: &mut String) {
        let mut placed: Vec<LabelBox> = timed
            .iter()
            .map(|t| {
                let (x, y) = (self.px(t.1), self.py(t.2));
                (x - 5.0, y - 5.0, x + 5.0, y + 5.0)
            })
            .chain(line_labels.iter().copied())
            .collect();
        for (name, ms, db, on) in timed {
            let (x, yy) = (self.px(*ms), self.py(*db));
            let tw = 7.0 * name.chars().count() as f64;
            let boxes = [
                (x + 6.0, yy - 18.0),
                (x + 6.0, yy + 4.0),
                (x - 6.0 - tw, yy - 18.0),
                (x - 6.0 - tw, yy + 4.0),
            ];
            let free = |&(bx, by): &(f64, f64)| {
                placed.iter().all(|&(px0, py0, px1, py1)| {
                    bx + tw <= px0 || bx >= px1 || by + 14.0 <= py0 || by >= py1
                })
            };
            let (bx, by) = boxes.iter().copied().find(|b| free(b)).unwrap_or(boxes[0]);
            placed.push((bx, by, bx + tw, by + 14.0));
            *s += &format!(
                "<circle cx=\"{x:.1}\" cy=\"{yy:.1}\" r=\"4\" fill=\"{}\"><title>{}: {} dB, {} ms{}</title></circle>\n<text x=\"{bx:.1}\" y=\"{:.1}\">{}</text>\n",
                if *on { "#e67e22" } else { "#1f77b4" },
                escape(name),
                fmt_psnr(*db),
                num(*ms),
                if *on { ", on the frontier" } else { "" },
                by + 11.0,
                escape(name)
            );
        }
    }
}

fn img(src: &str, alt: &str) -> String {
    format!(
        "<img src=\"{}\" alt=\"{}\" loading=\"lazy\">",
        escape(src),
        escape(alt)
    )
}

impl Report {
    /// The self-contained HTML page (module docs): settings, the table, the chart, the heat-map
    /// legend, then one card per image with its heat map and enlarged horizon crop.
    pub fn to_html(&self) -> String {
        let title = format!("texel filter report: {}", self.scene);
        let mut s = format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>{}</title>\n<style>\n\
             body {{ font-family: sans-serif; margin: 1.5em; color: #222; }}\n\
             table {{ border-collapse: collapse; }}\n\
             th, td {{ border: 1px solid #ccc; padding: 0.25em 0.6em; }}\n\
             td {{ text-align: right; font-variant-numeric: tabular-nums; }}\n\
             td:first-child {{ text-align: left; }}\n\
             .grid {{ display: flex; flex-wrap: wrap; gap: 1em; }}\n\
             figure {{ margin: 0; max-width: 420px; }}\n\
             figure img {{ width: 100%; image-rendering: pixelated; display: block; margin-bottom: 0.3em; }}\n\
             figcaption {{ font-size: 0.9em; }}\n\
             </style>\n</head>\n<body>\n<h1>{}</h1>\n",
            escape(&title),
            escape(&title)
        );
        s += &format!(
            "<p>{}x{} pixels; reference: {} samples per pixel; colour: {}. PSNR and SSIM against the \
             reference over the pixels the geometry covers; the band is the {} covered rows below the \
             horizon (the top of the coverage in each column). Rows marked (extra) are images rendered \
             elsewhere: they have no time, texel or memory numbers.</p>\n",
            self.width,
            self.height,
            self.spp,
            escape(&self.color),
            self.band_rows
        );
        if let Some(e) = &self.reference_error {
            s += &format!("<p>{}</p>\n", escape(&e.sentence()));
        }
        s += "<table>\n<tr>";
        let orbit = self.orbit.is_some();
        for h in table_header(orbit) {
            s += &format!("<th>{}</th>", escape(h));
        }
        s += "</tr>\n";
        for r in &self.rows {
            s += "<tr>";
            for c in row_cells(r, orbit) {
                s += &format!("<td>{}</td>", escape(&c));
            }
            s += "</tr>\n";
        }
        s += "</table>\n<h2>Quality against time</h2>\n";
        s += &chart_svg(self);
        let identical: Vec<&str> = self
            .rows
            .iter()
            .filter(|r| r.psnr_all.is_infinite())
            .map(|r| r.name.as_str())
            .collect();
        if !identical.is_empty() {
            s += &format!(
                "<p>Not plotted (identical to the reference, infinite PSNR): {}.</p>\n",
                escape(&identical.join(", "))
            );
        }
        s += &format!(
            "<h2>Images</h2>\n<p>Each card: the image, its error heat map (mean absolute RGB error in \
             8-bit units on the viridis ramp; black is not covered) and the horizon enlarged with \
             nearest neighbour.</p>\n{}",
            legend_svg(self.heat_map_max, 360)
        );
        s += "<div class=\"grid\">\n";
        s += "<figure>";
        s += &img(&self.reference_image, "reference");
        if let Some(c) = &self.reference_crop {
            s += &img(c, "reference, horizon enlarged");
        }
        s += &format!(
            "<figcaption>reference ({} spp)</figcaption></figure>\n",
            self.spp
        );
        for r in &self.rows {
            s += "<figure>";
            s += &img(&r.image, &r.name);
            if let Some(h) = &r.heat_map {
                s += &img(h, &format!("{}: error heat map", r.name));
            }
            if let Some(c) = &r.horizon_crop {
                s += &img(c, &format!("{}: horizon enlarged", r.name));
            }
            s += &format!(
                "<figcaption>{}{}: {} dB, band {} dB, SSIM {:.4}</figcaption></figure>\n",
                escape(&r.name),
                if r.extra { " (extra)" } else { "" },
                fmt_psnr(r.psnr_all),
                fmt_psnr(r.psnr_band),
                r.ssim
            );
        }
        s += "</div>\n</body>\n</html>\n";
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::tests::sample;

    #[test]
    fn escapes_everything() {
        assert_eq!(
            escape("<a href=\"x\">&'</a>"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;&lt;/a&gt;"
        );
        let mut r = sample();
        r.scene = "<script>alert(1)</script>".into();
        r.rows[0].image = "a\"onerror=\"x.png".into();
        let h = r.to_html();
        assert!(!h.contains("<script>"));
        assert!(h.contains("&lt;script&gt;"));
        assert!(!h.contains("a\"onerror"));
        assert!(h.contains("gpu &lt;a|b&gt;"));
    }

    #[test]
    fn page_structure() {
        let h = sample().to_html();
        assert!(h.starts_with("<!DOCTYPE html>"));
        assert!(h.trim_end().ends_with("</html>"));
        assert!(
            !h.contains("http://")
                || h.matches("http://").count()
                    == h.matches("xmlns=\"http://www.w3.org/2000/svg\"").count()
        );
        for f in [
            "reference.png",
            "reference_crop.png",
            "trilinear.png",
            "trilinear_error.png",
            "trilinear_crop.png",
            "extra_gpu.png",
        ] {
            assert!(h.contains(&format!("src=\"{f}\"")), "{f}");
        }
        assert_eq!(h.matches("<tr>").count(), 5);
        assert!(h.contains("Not plotted (identical to the reference, infinite PSNR): self."));
    }

    #[test]
    fn chart_places_points() {
        let svg = chart_svg(&sample());
        // Two timed finite rows, one dashed line for the extra.
        assert_eq!(svg.matches("<circle").count(), 2);
        assert_eq!(svg.matches("stroke-dasharray").count(), 1);
        // Time 3 ms and 12.5 ms on decades 1..100: x = LEFT + log10(ms) / 2 * width.
        let pw = CW - LEFT - RIGHT;
        let want = LEFT + 3f64.log10() / 2.0 * pw;
        assert!(svg.contains(&format!("cx=\"{want:.1}\"")), "{svg}");
        // Higher PSNR is higher on the page (smaller y).
        let cy = |name: &str| -> f64 {
            let i = svg.find(&format!("<title>{name}:")).unwrap();
            let pre = &svg[..i];
            let c = pre.rfind("cy=\"").unwrap();
            pre[c + 4..].split('"').next().unwrap().parse().unwrap()
        };
        assert!(cy("trilinear") < cy("nearest"));
        // The frontier: nearest (fastest) and self (infinite PSNR, not plotted); trilinear is
        // beaten by self at the same time. One plotted frontier point: no line, one orange dot.
        assert_eq!(sample().frontier().len(), 2);
        assert_eq!(svg.matches("fill=\"#e67e22\"><title>nearest").count(), 1);
        assert_eq!(svg.matches("<polyline").count(), 0);
        let empty = Report {
            rows: vec![],
            ..sample()
        };
        assert!(chart_svg(&empty).contains("no rows"));
    }

    #[test]
    fn nice_steps() {
        assert_eq!(nice_step(8.0), 1.0);
        assert_eq!(nice_step(15.0), 2.0);
        assert_eq!(nice_step(30.0), 5.0);
        assert_eq!(nice_step(0.8), 0.1);
    }
}
