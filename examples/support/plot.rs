//! Figures (PNG and SVG) and CSV files for the examples.
//!
//! Text is drawn by `ab_glyph` from the bundled DejaVu Sans
//! (`examples/support/DejaVuSans.ttf`, license beside it), so the examples
//! need no system fonts and no fontconfig.

use std::error::Error;
use std::io::Write;
use std::path::PathBuf;

use plotters::coord::Shift;
use plotters::prelude::*;

/// Result of the examples' I/O.
pub type Result<T> = std::result::Result<T, Box<dyn Error>>;

/// One curve of a panel.
pub struct Series {
    pub label: String,
    pub color: RGBColor,
    pub points: Vec<(f64, f64)>,
    /// Drawn thin over the others (estimates), else thick (true values).
    pub thin: bool,
    /// Drawn as dots (sparse events), else as a line.
    pub dots: bool,
}

impl Series {
    /// A solid line.
    pub fn line(label: &str, color: RGBColor, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            color,
            points,
            thin: false,
            dots: false,
        }
    }

    /// A thin line, drawn over the thick ones: an estimate over the truth.
    pub fn thin(label: &str, color: RGBColor, points: Vec<(f64, f64)>) -> Self {
        Self {
            thin: true,
            ..Self::line(label, color, points)
        }
    }

    /// Dots.
    pub fn dots(label: &str, color: RGBColor, points: Vec<(f64, f64)>) -> Self {
        Self {
            dots: true,
            ..Self::line(label, color, points)
        }
    }
}

/// One panel (a chart sharing the figure's x axis).
pub struct Panel {
    pub y_label: String,
    pub series: Vec<Series>,
    /// A magnified view of `x ∈ [a, b]`, drawn inside the panel.
    pub inset: Option<(f64, f64)>,
    /// Logarithmic y axis.
    pub log_y: bool,
}

impl Panel {
    /// A panel with a linear y axis and no inset.
    pub fn new(y_label: &str, series: Vec<Series>) -> Self {
        Self {
            y_label: y_label.into(),
            series,
            inset: None,
            log_y: false,
        }
    }

    /// The same panel with a magnified inset over `x ∈ [a, b]`.
    pub fn with_inset(self, a: f64, b: f64) -> Self {
        Self {
            inset: Some((a, b)),
            ..self
        }
    }

    /// The same panel with a logarithmic y axis.
    pub fn log(self) -> Self {
        Self {
            log_y: true,
            ..self
        }
    }
}

/// Where the examples write: `out/` at the workspace root, or `$MOREAU_OUT`.
pub fn out_dir() -> Result<PathBuf> {
    let dir = std::env::var_os("MOREAU_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("out"));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let font: &'static [u8] = include_bytes!("DejaVuSans.ttf");
        if plotters::style::register_font("sans-serif", FontStyle::Normal, font).is_err() {
            eprintln!("warning: the bundled font could not be loaded; figures will lack text");
        }
    });
}

/// Writes `out/<stem>.png` and `out/<stem>.svg`: the panels stacked, sharing
/// the x axis. Returns the two paths.
pub fn figure(stem: &str, title: &str, x_label: &str, panels: &[Panel]) -> Result<[PathBuf; 2]> {
    register_font();
    let dir = out_dir()?;
    let size = (1100, 330 * panels.len() as u32 + 60);
    let png = dir.join(format!("{stem}.png"));
    let svg = dir.join(format!("{stem}.svg"));
    {
        let root = BitMapBackend::new(&png, size).into_drawing_area();
        draw(&root, title, x_label, panels, true)?;
        root.present()?;
    }
    {
        let root = SVGBackend::new(&svg, size).into_drawing_area();
        draw(&root, title, x_label, panels, false)?;
        root.present()?;
    }
    Ok([png, svg])
}

/// `segments`: draw lines segment by segment (bitmaps: plotters' thick
/// polylines draw unbounded miter spikes where a line turns back on
/// itself; SVG viewers cap them, so SVG keeps polylines).
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    x_label: &str,
    panels: &[Panel],
    segments: bool,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 24))?;
    let areas = root.split_evenly((panels.len(), 1));
    let x_range = x_extent(panels);
    for (area, panel) in areas.iter().zip(panels) {
        chart(area, panel, x_range, x_label, false, segments)?;
        if let Some((a, b)) = panel.inset {
            let (w, h) = area.dim_in_pixel();
            let inset = area.clone().shrink(
                ((w as f64 * 0.52) as i32, (h as f64 * 0.08) as i32),
                ((w as f64 * 0.40) as u32, (h as f64 * 0.50) as u32),
            );
            inset.fill(&WHITE)?;
            inset.draw(&Rectangle::new(
                [
                    (0, 0),
                    (
                        inset.dim_in_pixel().0 as i32 - 1,
                        inset.dim_in_pixel().1 as i32 - 1,
                    ),
                ],
                BLACK.mix(0.4),
            ))?;
            chart(&inset, panel, (a, b), "", true, segments)?;
        }
    }
    Ok(())
}

fn x_extent(panels: &[Panel]) -> (f64, f64) {
    let xs = panels
        .iter()
        .flat_map(|p| p.series.iter())
        .flat_map(|s| s.points.iter().map(|p| p.0));
    let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    if lo < hi { (lo, hi) } else { (0.0, 1.0) }
}

fn y_extent(panel: &Panel, x: (f64, f64)) -> (f64, f64) {
    let ys = panel
        .series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|p| p.0 >= x.0 && p.0 <= x.1 && p.1.is_finite())
        .filter(|p| !panel.log_y || p.1 > 0.0)
        .map(|p| p.1);
    let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
        (lo.min(y), hi.max(y))
    });
    if lo >= hi {
        return if lo.is_finite() {
            (lo - 1.0, lo + 1.0)
        } else {
            (0.0, 1.0)
        };
    }
    if panel.log_y {
        (lo.max(1e-12), hi * 2.0)
    } else {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    }
}

fn chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    x: (f64, f64),
    x_label: &str,
    inset: bool,
    segments: bool,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let y = y_extent(panel, x);
    let font = if inset { 12 } else { 16 };
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(if inset { 4 } else { 10 })
        .x_label_area_size(if inset { 20 } else { 36 })
        .y_label_area_size(if inset { 44 } else { 80 });
    let visible: Vec<&Series> = panel
        .series
        .iter()
        .filter(|s| !s.points.is_empty())
        .collect();
    macro_rules! body {
        ($chart:expr) => {{
            let mut chart = $chart;
            let mut mesh = chart.configure_mesh();
            mesh.label_style(("sans-serif", font))
                .light_line_style(WHITE.mix(0.0));
            if panel.log_y {
                mesh.y_label_formatter(&|y: &f64| format!("{y:.0e}"));
            }
            if !inset {
                mesh.x_desc(x_label).y_desc(panel.y_label.as_str());
            }
            mesh.draw()?;
            for s in &visible {
                // plotters does not clip lines to the chart: clamp into it
                // (and keep non-positive values on a log axis at its floor)
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .filter(|p| p.0 >= x.0 && p.0 <= x.1 && !p.1.is_nan())
                    .map(|p| (p.0, p.1.clamp(y.0, y.1)))
                    .collect();
                let pts = decimate(&pts, x, area.dim_in_pixel().0 as usize);
                let color = s.color;
                let style = color.stroke_width(if s.thin { 1 } else { 3 });
                let drawn = if s.dots {
                    chart.draw_series(
                        pts.into_iter()
                            .map(move |p| Circle::new(p, 2, color.filled())),
                    )?
                } else if segments {
                    chart.draw_series(
                        pts.windows(2)
                            .map(move |w| PathElement::new(vec![w[0], w[1]], style)),
                    )?
                } else {
                    chart.draw_series(LineSeries::new(pts, style))?
                };
                if !inset {
                    drawn.label(s.label.as_str()).legend(move |(px, py)| {
                        PathElement::new(vec![(px, py), (px + 20, py)], color.stroke_width(2))
                    });
                }
            }
            if !inset {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperLeft)
                    .label_font(("sans-serif", 14))
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK.mix(0.3))
                    .draw()?;
            }
        }};
    }
    if panel.log_y {
        body!(builder.build_cartesian_2d(x.0..x.1, (y.0..y.1).log_scale())?);
    } else {
        body!(builder.build_cartesian_2d(x.0..x.1, y.0..y.1)?);
    }
    Ok(())
}

/// Keeps, of every one of `columns` slices of `x`, the first, lowest,
/// highest and last point, in time order: the drawn envelope is unchanged
/// and a figure of any length stays small.
fn decimate(points: &[(f64, f64)], x: (f64, f64), columns: usize) -> Vec<(f64, f64)> {
    let width = (x.1 - x.0) / columns.max(1) as f64;
    let column = |p: &(f64, f64)| ((p.0 - x.0) / width) as i64;
    let mut out = Vec::new();
    let mut start = 0;
    while start < points.len() {
        let c = column(&points[start]);
        let end = start
            + points[start..]
                .iter()
                .take_while(|p| column(p) == c)
                .count();
        let slice = &points[start..end];
        let lowest = (0..slice.len())
            .min_by(|&a, &b| slice[a].1.total_cmp(&slice[b].1))
            .unwrap_or(0);
        let highest = (0..slice.len())
            .max_by(|&a, &b| slice[a].1.total_cmp(&slice[b].1))
            .unwrap_or(0);
        let mut keep = vec![0, lowest, highest, slice.len() - 1];
        keep.sort_unstable();
        keep.dedup();
        out.extend(keep.into_iter().map(|i| slice[i]));
        start = end;
    }
    out
}

/// Writes `out/<stem>.csv` with a header line and one row per record.
pub fn csv(
    stem: &str,
    header: &[&str],
    rows: impl IntoIterator<Item = Vec<f64>>,
) -> Result<PathBuf> {
    let path = out_dir()?.join(format!("{stem}.csv"));
    let mut file = std::io::BufWriter::new(std::fs::File::create(&path)?);
    writeln!(file, "{}", header.join(","))?;
    for row in rows {
        let text: Vec<String> = row.iter().map(|x| format!("{x:e}")).collect();
        writeln!(file, "{}", text.join(","))?;
    }
    file.flush()?;
    Ok(path)
}

/// Prints, after a blank line, the files an example wrote.
pub fn announce(paths: &[&std::path::Path]) {
    let list: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    println!();
    println!("wrote {}", list.join(", "));
}
