//! Minimal SVG plotting: line/marker/bar series on linear axes, shaded bands
//! and highlighted x-windows, composed into grids (corner plots). A plot
//! may fix its y range ([`Plot::y_range`]): what leaves it is clipped at the
//! frame and marked there by a triangle pointing the way it left.
//!
//! Written here rather than with `plotters`: plotters' text layout pulls in a
//! font backend (font-kit/freetype or ab_glyph with a bundled font) for what
//! are plain `<text>` elements in SVG; the few hundred lines below give
//! deterministic, byte-identical SVG with no system dependency.

use std::fmt::Write;

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Style {
    Line,
    Dashed,
    Markers,
    /// Vertical bars from y = 0 at each x (width in x units).
    Bars(f64),
    /// Horizontal bars from x = 0 at each y (height in y units).
    HBars(f64),
}

/// One named data series.
#[derive(Debug, Clone)]
pub struct Series {
    pub label: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub style: Style,
    /// CSS colour; `None` takes the next colour of the palette.
    pub color: Option<String>,
}

impl Series {
    /// A solid line.
    pub fn line(label: impl Into<String>, x: &[f64], y: &[f64]) -> Self {
        Series {
            label: label.into(),
            x: x.to_vec(),
            y: y.to_vec(),
            style: Style::Line,
            color: None,
        }
    }
    /// Markers only (measured data).
    pub fn markers(label: impl Into<String>, x: &[f64], y: &[f64]) -> Self {
        Series {
            label: label.into(),
            x: x.to_vec(),
            y: y.to_vec(),
            style: Style::Markers,
            color: None,
        }
    }
    /// A dashed line.
    pub fn dashed(label: impl Into<String>, x: &[f64], y: &[f64]) -> Self {
        Series {
            label: label.into(),
            x: x.to_vec(),
            y: y.to_vec(),
            style: Style::Dashed,
            color: None,
        }
    }
    /// Sets the colour.
    pub fn color(mut self, c: impl Into<String>) -> Self {
        self.color = Some(c.into());
        self
    }
    /// Sets the style.
    pub fn style(mut self, s: Style) -> Self {
        self.style = s;
        self
    }
}

/// A shaded band between `lower` and `upper` over `x` (e.g. a predictive band).
#[derive(Debug, Clone)]
pub struct Band {
    pub label: String,
    pub x: Vec<f64>,
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    pub color: String,
}

/// A single set of axes.
#[derive(Debug, Clone, Default)]
pub struct Plot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub bands: Vec<Band>,
    /// Highlighted x-intervals (e.g. flagged misfit windows), drawn shaded.
    pub windows: Vec<(f64, f64)>,
    /// Horizontal reference lines (y values), drawn dotted.
    pub hlines: Vec<f64>,
    /// Tick labels for the y axis instead of numbers (for bar charts of named terms).
    pub y_categories: Option<Vec<String>>,
    /// Tick labels for the x axis instead of numbers (for level names).
    pub x_categories: Option<Vec<String>>,
    /// The y axis's range instead of the data's: lines are clipped at the
    /// frame and points outside it drawn as triangles on the edge they
    /// left by, with a note saying so.
    pub y_range: Option<(f64, f64)>,
    pub width: f64,
    pub height: f64,
}

/// The colours series take in turn.
pub const PALETTE: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

impl Plot {
    /// Empty axes with a title and axis labels, 640 x 420 px.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Plot {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            width: 640.0,
            height: 420.0,
            ..Default::default()
        }
    }

    /// Adds a series.
    pub fn with(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }

    /// Adds a series in place.
    pub fn push(&mut self, s: Series) {
        self.series.push(s);
    }

    /// The complete SVG document.
    pub fn to_svg(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="Helvetica,Arial,sans-serif">"#,
            w = fmt(self.width),
            h = fmt(self.height)
        );
        let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
        self.draw(&mut out, 0.0, 0.0);
        out.push_str("</svg>\n");
        out
    }

    /// Data range over series, bands and windows, padded, with zero included for bars.
    fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let mut xs = Vec::new();
        let mut ys = Vec::new();
        for s in &self.series {
            for (&x, &y) in s.x.iter().zip(&s.y) {
                if x.is_finite() && y.is_finite() {
                    xs.push(x);
                    ys.push(y);
                }
            }
            match s.style {
                Style::Bars(_) => ys.push(0.0),
                Style::HBars(_) => xs.push(0.0),
                _ => {}
            }
        }
        for b in &self.bands {
            xs.extend(b.x.iter().copied().filter(|v| v.is_finite()));
            ys.extend(
                b.lower
                    .iter()
                    .chain(&b.upper)
                    .copied()
                    .filter(|v| v.is_finite()),
            );
        }
        ys.extend(self.hlines.iter().copied());
        let span = |v: &[f64]| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if !lo.is_finite() {
                (0.0, 1.0)
            } else if hi - lo <= 1e-300 {
                (lo - 0.5 * lo.abs().max(1.0), hi + 0.5 * hi.abs().max(1.0))
            } else {
                (lo, hi)
            }
        };
        let (x0, x1) = span(&xs);
        let (y0, y1) = span(&ys);
        let px = if self
            .series
            .iter()
            .any(|s| matches!(s.style, Style::Bars(_) | Style::HBars(_)))
        {
            0.05 * (x1 - x0)
        } else {
            0.0
        };
        if let Some((lo, hi)) = self.y_range.filter(|(lo, hi)| hi > lo) {
            return ((x0 - px, x1 + px), (lo, hi));
        }
        let py = 0.05 * (y1 - y0);
        ((x0 - px, x1 + px), (y0 - py, y1 + py))
    }

    /// Draws the axes with their top-left corner at (ox, oy).
    pub fn draw(&self, out: &mut String, ox: f64, oy: f64) {
        let (ml, mr, mt, mb) = (
            if self.y_categories.is_some() {
                130.0
            } else {
                70.0
            },
            20.0,
            34.0,
            50.0,
        );
        let (pw, ph) = (self.width - ml - mr, self.height - mt - mb);
        let ((x0, x1), (y0, y1)) = self.ranges();
        let sx = |x: f64| ox + ml + (x - x0) / (x1 - x0) * pw;
        let sy = |y: f64| oy + mt + ph - (y - y0) / (y1 - y0) * ph;
        let _ = writeln!(
            out,
            r#"<text x="{}" y="{}" font-size="14" text-anchor="middle">{}</text>"#,
            fmt(ox + ml + pw / 2.0),
            fmt(oy + 20.0),
            esc(&self.title)
        );
        for &(a, b) in &self.windows {
            // (from, to) of a record whose axis decreases (a compression's stretch) too.
            let (a, b) = (a.min(b).max(x0), a.max(b).min(x1));
            if b > a {
                let _ = writeln!(
                    out,
                    r##"<rect x="{}" y="{}" width="{}" height="{}" fill="#ffcc00" fill-opacity="0.25"/>"##,
                    fmt(sx(a)),
                    fmt(oy + mt),
                    fmt(sx(b) - sx(a)),
                    fmt(ph)
                );
            }
        }
        // Grid and ticks.
        let xticks = match &self.x_categories {
            Some(c) => (0..c.len()).map(|i| (i as f64, c[i].clone())).collect(),
            None => labelled(ticks(x0, x1)),
        };
        let yticks = match &self.y_categories {
            Some(c) => (0..c.len()).map(|i| (i as f64, c[i].clone())).collect(),
            None => labelled(ticks(y0, y1)),
        };
        for (t, l) in &xticks {
            let x = sx(*t);
            let _ = writeln!(
                out,
                r##"<line x1="{x}" y1="{}" x2="{x}" y2="{}" stroke="#e0e0e0"/>"##,
                fmt(oy + mt),
                fmt(oy + mt + ph),
                x = fmt(x)
            );
            let _ = writeln!(
                out,
                r#"<text x="{}" y="{}" font-size="11" text-anchor="middle">{}</text>"#,
                fmt(x),
                fmt(oy + mt + ph + 16.0),
                esc(l)
            );
        }
        for (t, l) in &yticks {
            let y = sy(*t);
            let _ = writeln!(
                out,
                r##"<line x1="{}" y1="{y}" x2="{}" y2="{y}" stroke="#e0e0e0"/>"##,
                fmt(ox + ml),
                fmt(ox + ml + pw),
                y = fmt(y)
            );
            let _ = writeln!(
                out,
                r#"<text x="{}" y="{}" font-size="11" text-anchor="end">{}</text>"#,
                fmt(ox + ml - 5.0),
                fmt(y + 4.0),
                esc(l)
            );
        }
        let _ = writeln!(
            out,
            r#"<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="black"/>"#,
            fmt(ox + ml),
            fmt(oy + mt),
            fmt(pw),
            fmt(ph)
        );
        let _ = writeln!(
            out,
            r#"<text x="{}" y="{}" font-size="12" text-anchor="middle">{}</text>"#,
            fmt(ox + ml + pw / 2.0),
            fmt(oy + self.height - 10.0),
            esc(&self.x_label)
        );
        let (lx, ly) = (ox + 14.0, oy + mt + ph / 2.0);
        let _ = writeln!(
            out,
            r#"<text x="{}" y="{}" font-size="12" text-anchor="middle" transform="rotate(-90 {} {})">{}</text>"#,
            fmt(lx),
            fmt(ly),
            fmt(lx),
            fmt(ly),
            esc(&self.y_label)
        );
        for &h in &self.hlines {
            let _ = writeln!(
                out,
                r##"<line x1="{}" y1="{y}" x2="{}" y2="{y}" stroke="#555" stroke-dasharray="2,3"/>"##,
                fmt(ox + ml),
                fmt(ox + ml + pw),
                y = fmt(sy(h))
            );
        }
        for b in &self.bands {
            let mut pts = String::new();
            for (x, y) in
                b.x.iter()
                    .zip(&b.upper)
                    .chain(b.x.iter().zip(&b.lower).rev())
            {
                let _ = write!(pts, "{},{} ", fmt(sx(*x)), fmt(sy(*y)));
            }
            let _ = writeln!(
                out,
                r#"<polygon points="{}" fill="{}" fill-opacity="0.25" stroke="none"/>"#,
                pts.trim_end(),
                b.color
            );
        }
        let mut legend = Vec::new();
        // (x, above the frame, colour) of every place a series leaves it.
        let mut exits: Vec<(f64, bool, String)> = Vec::new();
        for (k, s) in self.series.iter().enumerate() {
            let c = s
                .color
                .clone()
                .unwrap_or_else(|| PALETTE[k % PALETTE.len()].to_string());
            match s.style {
                Style::Line | Style::Dashed => {
                    // Each segment clipped to the y range; where it leaves
                    // or re-enters the frame, a triangle on the edge.
                    let mut d = String::new();
                    let mut pen = false;
                    for (a, b) in s.x.iter().zip(&s.y).zip(s.x.iter().zip(&s.y).skip(1)) {
                        let (a, b) = ((*a.0, *a.1), (*b.0, *b.1));
                        if !(a.0.is_finite()
                            && a.1.is_finite()
                            && b.0.is_finite()
                            && b.1.is_finite())
                        {
                            pen = false;
                            continue;
                        }
                        let Some((p, q, entered, left)) = clip_segment(a, b, y0, y1) else {
                            pen = false;
                            continue;
                        };
                        if entered || !pen {
                            let _ = write!(d, "M{},{} ", fmt(sx(p.0)), fmt(sy(p.1)));
                        }
                        if entered {
                            exits.push((p.0, a.1 > y1, c.clone()));
                        }
                        let _ = write!(d, "L{},{} ", fmt(sx(q.0)), fmt(sy(q.1)));
                        pen = !left;
                        if left {
                            exits.push((q.0, b.1 > y1, c.clone()));
                        }
                    }
                    let dash = if s.style == Style::Dashed {
                        r#" stroke-dasharray="6,4""#
                    } else {
                        ""
                    };
                    let _ = writeln!(
                        out,
                        r#"<path d="{}" fill="none" stroke="{c}" stroke-width="1.8"{dash}/>"#,
                        d.trim_end()
                    );
                }
                Style::Markers => {
                    for (x, y) in s.x.iter().zip(&s.y) {
                        if x.is_finite() && y.is_finite() && !(y0..=y1).contains(y) {
                            exits.push((*x, *y > y1, c.clone()));
                        } else if x.is_finite() && y.is_finite() {
                            let _ = writeln!(
                                out,
                                r#"<circle cx="{}" cy="{}" r="2.6" fill="none" stroke="{c}"/>"#,
                                fmt(sx(*x)),
                                fmt(sy(*y))
                            );
                        }
                    }
                }
                Style::Bars(w) => {
                    for (x, y) in s.x.iter().zip(&s.y) {
                        let (a, b) = (sx(x - w / 2.0), sx(x + w / 2.0));
                        let (top, bot) = (sy(y.max(0.0)), sy(y.min(0.0)));
                        let _ = writeln!(
                            out,
                            r#"<rect x="{}" y="{}" width="{}" height="{}" fill="{c}"/>"#,
                            fmt(a),
                            fmt(top),
                            fmt(b - a),
                            fmt(bot - top)
                        );
                    }
                }
                Style::HBars(hgt) => {
                    for (x, y) in s.x.iter().zip(&s.y) {
                        let (l, r) = (sx(x.min(0.0)), sx(x.max(0.0)));
                        let (top, bot) = (sy(y + hgt / 2.0), sy(y - hgt / 2.0));
                        let _ = writeln!(
                            out,
                            r#"<rect x="{}" y="{}" width="{}" height="{}" fill="{c}"/>"#,
                            fmt(l),
                            fmt(top),
                            fmt(r - l),
                            fmt(bot - top)
                        );
                    }
                }
            }
            if !s.label.is_empty() {
                legend.push((s.label.clone(), c, s.style));
            }
        }
        for b in &self.bands {
            if !b.label.is_empty() {
                legend.push((b.label.clone(), b.color.clone(), Style::Bars(0.0)));
            }
        }
        if !legend.is_empty() {
            // A translucent box so the legend stays readable over data.
            let longest = legend
                .iter()
                .map(|(l, _, _)| l.chars().count())
                .max()
                .unwrap_or(0) as f64;
            let _ = writeln!(
                out,
                r##"<rect x="{}" y="{}" width="{}" height="{}" fill="white" fill-opacity="0.8" stroke="#cccccc"/>"##,
                fmt(ox + ml + 4.0),
                fmt(oy + mt + 2.0),
                fmt(34.0 + 6.2 * longest),
                fmt(16.0 * legend.len() as f64 + 4.0)
            );
        }
        for (i, (label, c, style)) in legend.iter().enumerate() {
            let y = oy + mt + 14.0 + 16.0 * i as f64;
            let x = ox + ml + 10.0;
            match style {
                Style::Markers => {
                    let _ = writeln!(
                        out,
                        r#"<circle cx="{}" cy="{}" r="3" fill="none" stroke="{c}"/>"#,
                        fmt(x + 9.0),
                        fmt(y - 4.0)
                    );
                }
                Style::Line | Style::Dashed => {
                    let _ = writeln!(
                        out,
                        r#"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{c}" stroke-width="2"/>"#,
                        fmt(x),
                        fmt(y - 4.0),
                        fmt(x + 18.0),
                        fmt(y - 4.0)
                    );
                }
                _ => {
                    let _ = writeln!(
                        out,
                        r#"<rect x="{}" y="{}" width="18" height="8" fill="{c}" fill-opacity="0.6"/>"#,
                        fmt(x),
                        fmt(y - 8.0)
                    );
                }
            }
            let _ = writeln!(
                out,
                r#"<text x="{}" y="{}" font-size="11">{}</text>"#,
                fmt(x + 24.0),
                fmt(y),
                esc(label)
            );
        }
        // Over the legend: a series leaving the frame is never hidden.
        for (x, above, c) in &exits {
            let (x, y) = (sx(*x), if *above { oy + mt } else { oy + mt + ph });
            // Pointing out of the frame, its tip on the edge.
            let d = if *above { -7.0 } else { 7.0 };
            let _ = writeln!(
                out,
                r#"<polygon class="off-frame" points="{},{} {},{} {},{}" fill="{c}"/>"#,
                fmt(x),
                fmt(y),
                fmt(x - 4.5),
                fmt(y - d),
                fmt(x + 4.5),
                fmt(y - d)
            );
        }
        if !exits.is_empty() {
            let _ = writeln!(
                out,
                r##"<text x="{}" y="{}" font-size="11" text-anchor="end" fill="#444">{}</text>"##,
                fmt(ox + ml + pw),
                fmt(oy + self.height - 10.0),
                esc("\u{25b2}\u{25bc} leaves the frame")
            );
        }
    }
}

/// Several plots in a grid of `cols` columns (e.g. a corner plot); `None`
/// leaves a cell empty.
pub fn grid_svg(cells: &[Option<Plot>], cols: usize, title: &str) -> String {
    let cols = cols.max(1);
    let rows = cells.len().div_ceil(cols);
    let cw = cells.iter().flatten().map(|p| p.width).fold(0.0, f64::max);
    // Each row as tall as its tallest plot.
    let heights: Vec<f64> = (0..rows)
        .map(|r| {
            cells[r * cols..((r + 1) * cols).min(cells.len())]
                .iter()
                .flatten()
                .map(|p| p.height)
                .fold(0.0, f64::max)
        })
        .collect();
    let tops: Vec<f64> = heights
        .iter()
        .scan(30.0, |y, h| {
            let top = *y;
            *y += h;
            Some(top)
        })
        .collect();
    let (w, h) = (cw * cols as f64, 30.0 + heights.iter().sum::<f64>());
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="Helvetica,Arial,sans-serif">"#,
        w = fmt(w),
        h = fmt(h)
    );
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        out,
        r#"<text x="{}" y="20" font-size="15" text-anchor="middle">{}</text>"#,
        fmt(w / 2.0),
        esc(title)
    );
    for (i, cell) in cells.iter().enumerate() {
        if let Some(p) = cell {
            p.draw(&mut out, (i % cols) as f64 * cw, tops[i / cols]);
        }
    }
    out.push_str("</svg>\n");
    out
}

/// A clipped segment: its two ends, whether it enters and whether it leaves.
type Clipped = ((f64, f64), (f64, f64), bool, bool);

/// The part of the segment `a`-`b` with y in `[lo, hi]` (Liang-Barsky in
/// y): its ends, and whether the segment enters (starts outside) and leaves
/// (ends outside) the range; `None` when no part is inside.
fn clip_segment(a: (f64, f64), b: (f64, f64), lo: f64, hi: f64) -> Option<Clipped> {
    let dy = b.1 - a.1;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-dy, a.1 - lo), (dy, hi - a.1)] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    let at = |t: f64| (a.0 + t * (b.0 - a.0), a.1 + t * dy);
    Some((at(t0), at(t1), t0 > 0.0, t1 < 1.0))
}

/// At most about `max` evenly spaced samples of `(x, y)` (the first and
/// the last kept): markers that show the data without hiding a fit drawn
/// over them.
pub fn thinned(x: &[f64], y: &[f64], max: usize) -> (Vec<f64>, Vec<f64>) {
    let n = x.len().min(y.len());
    let step = n.div_ceil(max.max(1)).max(1);
    let mut keep: Vec<usize> = (0..n).step_by(step).collect();
    if n > 0 && keep.last() != Some(&(n - 1)) {
        keep.push(n - 1);
    }
    (
        keep.iter().map(|&i| x[i]).collect(),
        keep.iter().map(|&i| y[i]).collect(),
    )
}

/// "Nice" tick positions (1, 2, 5 x 10^k steps) covering [lo, hi].
pub fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = hi - lo;
    if span.is_nan() || span <= 0.0 || !span.is_finite() {
        return vec![lo];
    }
    let raw = span / 6.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| span / s <= 7.0)
        .unwrap_or(10.0 * mag);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// Tick labels with just enough digits to tell neighbouring ticks apart:
/// fixed-point for magnitudes in [1e-3, 1e5), scientific otherwise.
fn labelled(t: Vec<f64>) -> Vec<(f64, String)> {
    let step = if t.len() > 1 {
        (t[1] - t[0]).abs()
    } else {
        t.first().map_or(1.0, |v| v.abs().max(1e-300))
    };
    let big = t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scientific = big > 0.0 && !(1e-3..1e5).contains(&big);
    t.into_iter()
        .map(|v| {
            let label = if v == 0.0 {
                "0".to_string()
            } else if scientific {
                // Significant digits needed so that one step changes the mantissa.
                let digits =
                    ((v.abs().log10().floor() - step.log10().floor()).max(0.0) as usize).min(12);
                format!("{v:.digits$e}")
            } else {
                let decimals = (-step.log10().floor()).max(0.0) as usize;
                format!("{v:.decimals$}")
            };
            (v, label)
        })
        .collect()
}

/// Coordinates with two decimals: enough for the screen, stable across runs.
fn fmt(v: f64) -> String {
    if v.is_finite() {
        let s = format!("{v:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        "0".into()
    }
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_nice_and_cover_range() {
        assert_eq!(ticks(0.0, 10.0), vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        let t = ticks(0.013, 0.087);
        assert!(
            t.len() >= 3 && t[0] >= 0.013 && *t.last().unwrap() <= 0.087,
            "{t:?}"
        );
    }

    #[test]
    fn tick_labels_are_distinct() {
        for (lo, hi) in [
            (0.0019, 0.00212),
            (6.5e-4, 7.1e-4),
            (0.0, 10.0),
            (0.95, 1.02),
            (1e5, 3e5),
        ] {
            let l: Vec<String> = labelled(ticks(lo, hi))
                .into_iter()
                .map(|(_, s)| s)
                .collect();
            let mut u = l.clone();
            u.dedup();
            assert_eq!(u.len(), l.len(), "{lo}..{hi}: {l:?}");
        }
        assert_eq!(labelled(ticks(0.0, 10.0)).last().unwrap().1, "10");
    }

    #[test]
    fn svg_is_deterministic_and_well_formed() {
        let x: Vec<f64> = (0..20).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = x.iter().map(|v| v * v).collect();
        let mut p = Plot::new("t < 1", "x", "y")
            .with(Series::markers("data", &x, &y))
            .with(Series::line("fit", &x, &y));
        p.windows.push((0.5, 1.0));
        let a = p.to_svg();
        assert_eq!(a, p.to_svg());
        assert!(a.starts_with("<svg") && a.trim_end().ends_with("</svg>"));
        assert!(a.contains("t &lt; 1"));
        assert_eq!(a.matches("<circle").count(), 20 + 1);
    }

    #[test]
    fn a_fixed_y_range_clips_lines_and_marks_where_they_leave() {
        let x = [0.0, 1.0, 2.0, 3.0];
        let mut p = Plot::new("t", "x", "y")
            .with(Series::line("fit", &x, &[0.0, 0.5, 3e21, 0.5]))
            .with(Series::markers("data", &x, &[0.0, 0.5, -5.0, 0.5]));
        p.y_range = Some((-1.0, 1.0));
        let svg = p.to_svg();
        // Leaves upwards and comes back (two triangles), one marker below.
        assert_eq!(svg.matches(r#"class="off-frame""#).count(), 3, "{svg}");
        assert_eq!(svg.matches("<circle").count(), 3 + 1);
        assert!(svg.contains("leaves the frame"));
        // Nothing drawn beyond the frame's top (y = 34) or bottom (420 - 50).
        let path = svg.lines().find(|l| l.starts_with("<path")).unwrap();
        for point in path.split(['M', 'L', '"']).filter(|t| t.contains(',')) {
            let y: f64 = point.trim().split(',').nth(1).unwrap().parse().unwrap();
            assert!((34.0..=370.0).contains(&y), "{y} in {path}");
        }
        // Without a range the same line sets the axis and nothing is marked.
        p.y_range = None;
        assert!(!p.to_svg().contains("off-frame"));
    }

    #[test]
    fn thinning_keeps_the_ends_and_at_most_about_max_points() {
        let x: Vec<f64> = (0..1200).map(f64::from).collect();
        let (tx, ty) = thinned(&x, &x, 60);
        assert!(tx.len() <= 61 && tx.len() >= 59, "{}", tx.len());
        assert_eq!((tx[0], *tx.last().unwrap()), (0.0, 1199.0));
        assert_eq!(tx, ty);
        assert_eq!(thinned(&x[..5], &x[..5], 60).0.len(), 5);
    }
}
