//! Line charts written as PNG files, for the benchmark figures: cumulative geodesic-error
//! curves (x: error threshold, y: fraction of vertices within it, one line per method),
//! accuracy against point density.
//!
//! Pure Rust and no system library: [`plotters`] draws into memory, its `ab_glyph` feature
//! renders the text from a TrueType font file found at run time ([`FONT_ENV`], then
//! [`FONT_PATHS`]), and [`png`] writes the file once the whole chart is drawn, so a failure
//! leaves no file behind. Without a font the chart is still drawn, without its text, and
//! [`Rendered::font`] says so.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use shapecorr::{Error, Result};

/// Width and height of the PNG, in pixels.
pub const SIZE: (u32, u32) = (800, 600);

/// Line colours, one per series in order: the Tableau 10 palette less its grey (grey would be
/// confused with the grid and the anti-aliased black text), distinct under the common colour
/// vision deficiencies. A chart holds at most this many series.
pub const PALETTE: [RGBColor; 9] = [
    RGBColor(31, 119, 180),  // blue
    RGBColor(255, 127, 14),  // orange
    RGBColor(44, 160, 44),   // green
    RGBColor(214, 39, 40),   // red
    RGBColor(148, 103, 189), // purple
    RGBColor(140, 86, 75),   // brown
    RGBColor(227, 119, 194), // pink
    RGBColor(188, 189, 34),  // olive
    RGBColor(23, 190, 207),  // cyan
];

/// Environment variable naming the TrueType/OpenType font for the text; when it is set, a
/// font that cannot be read is an error rather than a silent fallback.
pub const FONT_ENV: &str = "SHAPECORR_FONT";

/// Font files tried in order when [`FONT_ENV`] is not set: DejaVu Sans (Debian/Ubuntu package
/// `fonts-dejavu-core`, Fedora, Arch), Liberation Sans, FreeSans, then macOS and Windows Arial.
pub const FONT_PATHS: [&str; 10] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/freefont/FreeSans.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "/Library/Fonts/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

/// Layout, in pixels: outer margin, title band, room right of the plot for the last x tick
/// label, the x and y label areas, line width.
const MARGIN: u32 = 12;
const TITLE_HEIGHT: u32 = 40;
const RIGHT_PAD: u32 = 16;
const X_LABEL_AREA: u32 = 55;
const Y_LABEL_AREA: u32 = 70;
const LINE_WIDTH: u32 = 2;
/// Font sizes, in pixels.
const TITLE_FONT: f64 = 24.0;
const AXIS_DESC_FONT: f64 = 18.0;
const TICK_FONT: f64 = 15.0;
const LEGEND_FONT: f64 = 16.0;
/// The family name the font is registered under; plotters' default for tick labels.
const FAMILY: &str = "sans-serif";

/// One line of a chart: its legend label and its points `(x, y)`, drawn in the given order.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// Title, axis labels and axis ranges `(min, max)` of a chart; points outside the ranges are
/// clipped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chart<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
}

/// What [`line_chart_png`] drew.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rendered {
    /// The font file the text was drawn with. `None`: no font was found (see [`FONT_PATHS`]),
    /// so the PNG has the lines, grid and frame but no title, axis labels, tick labels or
    /// legend; series `i` is still drawn in `PALETTE[i]`.
    pub font: Option<PathBuf>,
}

/// Draws `series` as lines (series `i` in `PALETTE[i]`, with a legend) on axes `chart`, and
/// writes an 800x600 RGB PNG to `path`. The file is written only if the whole chart was drawn.
///
/// Errors: `InvalidParameter` for an empty or non-finite range, a non-finite point or more
/// series than [`PALETTE`] has colours; `File` when the font named by [`FONT_ENV`] cannot be
/// used or the file cannot be written.
pub fn line_chart_png(path: &Path, chart: &Chart, series: &[Series]) -> Result<Rendered> {
    validate(chart, series)?;
    let font = font()?;
    let rgb = render(chart, series, font.is_some())
        .map_err(|reason| Error::file(path, format!("drawing the chart: {reason}")))?;
    let png =
        encode_png(&rgb, SIZE).map_err(|e| Error::file(path, format!("encoding the PNG: {e}")))?;
    std::fs::write(path, png).map_err(|e| Error::file(path, format!("writing the PNG: {e}")))?;
    Ok(Rendered { font })
}

fn validate(chart: &Chart, series: &[Series]) -> Result<()> {
    for (name, (lo, hi)) in [("x_range", chart.x_range), ("y_range", chart.y_range)] {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(Error::InvalidParameter {
                name,
                reason: format!("got ({lo}, {hi}); it must be finite with min < max"),
            });
        }
    }
    if series.len() > PALETTE.len() {
        return Err(Error::InvalidParameter {
            name: "series",
            reason: format!(
                "got {} series; a chart has at most {} distinct colours, split it",
                series.len(),
                PALETTE.len()
            ),
        });
    }
    for s in series {
        if let Some((i, p)) = s
            .points
            .iter()
            .enumerate()
            .find(|(_, (x, y))| !(x.is_finite() && y.is_finite()))
        {
            return Err(Error::InvalidParameter {
                name: "series",
                reason: format!(
                    "point {i} of series `{}` is {p:?}; coordinates must be finite",
                    s.label
                ),
            });
        }
    }
    Ok(())
}

/// The font for the text, registered with plotters once per process: the file named by
/// [`FONT_ENV`] if set (an error if unusable), else the first usable one of [`FONT_PATHS`],
/// else none.
fn font() -> Result<Option<PathBuf>> {
    static FONT: OnceLock<std::result::Result<Option<PathBuf>, (PathBuf, String)>> =
        OnceLock::new();
    FONT.get_or_init(|| match std::env::var_os(FONT_ENV) {
        Some(path) => {
            let path = PathBuf::from(path);
            register(&path)
                .map(|()| Some(path.clone()))
                .map_err(|reason| (path, format!("{reason} (named by {FONT_ENV})")))
        }
        None => Ok(FONT_PATHS
            .iter()
            .map(PathBuf::from)
            .find(|path| register(path).is_ok())),
    })
    .clone()
    .map_err(|(path, reason)| Error::file(path, reason))
}

/// Reads a font file and registers it as [`FAMILY`]. plotters keeps `&'static` font bytes, so
/// they are leaked: at most once per process, as [`font`] runs once.
fn register(path: &Path) -> std::result::Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read the font: {e}"))?;
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    plotters::style::register_font(FAMILY, FontStyle::Normal, bytes)
        .map_err(|_| "not a TrueType/OpenType font ab_glyph can read".to_string())
}

/// Draws the chart into an RGB8 buffer of [`SIZE`]; with `text` false, draws no text at all
/// (plotters fails on text without a registered font). The layout is the same either way.
fn render(chart: &Chart, series: &[Series], text: bool) -> std::result::Result<Vec<u8>, String> {
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; 3 * w as usize * h as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        draw(&root, chart, series, text).map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(rgb)
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &Chart,
    series: &[Series],
    text: bool,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let root = root.margin(MARGIN, MARGIN, MARGIN, MARGIN);
    let (title_area, plot_area) = root.split_vertically(TITLE_HEIGHT);
    if text {
        let (tw, th) = title_area.dim_in_pixel();
        let style = TextStyle::from((FAMILY, TITLE_FONT).into_font())
            .pos(Pos::new(HPos::Center, VPos::Center));
        title_area.draw_text(chart.title, &style, (tw as i32 / 2, th as i32 / 2))?;
    }

    let x: Range<f64> = chart.x_range.0..chart.x_range.1;
    let y: Range<f64> = chart.y_range.0..chart.y_range.1;
    let mut ctx = ChartBuilder::on(&plot_area)
        .margin_right(RIGHT_PAD)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x.clone(), y.clone())?;

    let mut mesh = ctx.configure_mesh();
    // No more light lines than bold ones, i.e. a grid at the tick labels only: plotters'
    // default of up to ten light lines between two bold ones made the chart busy.
    mesh.x_max_light_lines(1).y_max_light_lines(1);
    if text {
        mesh.x_desc(chart.x_label)
            .y_desc(chart.y_label)
            .label_style((FAMILY, TICK_FONT))
            .axis_desc_style((FAMILY, AXIS_DESC_FONT));
    } else {
        // Tick labels and axis names are text; the grid lines stay.
        mesh.disable_x_axis().disable_y_axis();
    }
    mesh.draw()?;

    // plotters does not clip: a line leaving the ranges would run over the labels and margins.
    let area = ctx.plotting_area().clone();
    for (s, &colour) in series.iter().zip(PALETTE.iter()) {
        let style = colour.stroke_width(LINE_WIDTH);
        for part in clip_polyline(&s.points, &x, &y) {
            area.draw(&PathElement::new(part, style))?;
        }
        if text {
            // An empty series stands in for the line in the legend only.
            ctx.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?
                .label(s.label.as_str())
                .legend(move |(px, py)| PathElement::new(vec![(px, py), (px + 24, py)], style));
        }
    }

    // Frame around the plotting area, drawn over the line ends.
    area.draw(&Rectangle::new(
        [(x.start, y.end), (x.end, y.start)],
        BLACK.stroke_width(1),
    ))?;

    if text && !series.is_empty() {
        ctx.configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .margin(12)
            .label_font((FAMILY, LEGEND_FONT))
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .draw()?;
    }
    Ok(())
}

/// Splits a polyline into the parts inside the box `x` by `y`, each segment clipped to the box
/// (Liang-Barsky), so a line leaving the box stops at its edge.
fn clip_polyline(points: &[(f64, f64)], x: &Range<f64>, y: &Range<f64>) -> Vec<Vec<(f64, f64)>> {
    let mut parts: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    for pair in points.windows(2) {
        match clip_segment(pair[0], pair[1], x, y) {
            Some((a, b)) => {
                if current.last() != Some(&a) {
                    if current.len() > 1 {
                        parts.push(std::mem::take(&mut current));
                    }
                    current.clear();
                    current.push(a);
                }
                current.push(b);
            }
            None => {
                if current.len() > 1 {
                    parts.push(std::mem::take(&mut current));
                }
                current.clear();
            }
        }
    }
    if current.len() > 1 {
        parts.push(current);
    }
    parts
}

/// Liang-Barsky: the part of segment `p`-`q` inside the closed box, or `None`.
fn clip_segment(
    p: (f64, f64),
    q: (f64, f64),
    x: &Range<f64>,
    y: &Range<f64>,
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (den, num) in [
        (-dx, p.0 - x.start),
        (dx, x.end - p.0),
        (-dy, p.1 - y.start),
        (dy, y.end - p.1),
    ] {
        if den == 0.0 {
            if num < 0.0 {
                return None;
            }
        } else {
            let t = num / den;
            if den < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    (t0 <= t1).then(|| {
        let at = |t: f64| {
            if t == 0.0 {
                p
            } else if t == 1.0 {
                q
            } else {
                (p.0 + t * dx, p.1 + t * dy)
            }
        };
        (at(t0), at(t1))
    })
}

/// Encodes an RGB8 buffer as PNG bytes.
fn encode_png(rgb: &[u8], (w, h): (u32, u32)) -> std::result::Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A PNG file in the temp folder, removed when dropped.
    struct TempPng(PathBuf);
    impl TempPng {
        fn new(name: &str) -> Self {
            let file = format!("shapecorr-plot-{}-{name}.png", std::process::id());
            let path = std::env::temp_dir().join(file);
            let _ = std::fs::remove_file(&path);
            TempPng(path)
        }
    }
    impl Drop for TempPng {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.0);
        }
    }

    /// An RGB8 image: width, height, pixels row by row.
    struct Image {
        w: usize,
        h: usize,
        rgb: Vec<u8>,
    }
    impl Image {
        fn decode(path: &Path) -> Image {
            let bytes = std::fs::read(path).unwrap();
            let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
            let mut reader = decoder.read_info().unwrap();
            let mut rgb = vec![0; reader.output_buffer_size().unwrap()];
            let info = reader.next_frame(&mut rgb).unwrap();
            assert_eq!(info.color_type, png::ColorType::Rgb);
            assert_eq!(info.bit_depth, png::BitDepth::Eight);
            rgb.truncate(info.buffer_size());
            Image {
                w: info.width as usize,
                h: info.height as usize,
                rgb,
            }
        }
        fn px(&self, x: usize, y: usize) -> [u8; 3] {
            let i = 3 * (y * self.w + x);
            [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
        }
        fn is(&self, x: usize, y: usize, c: RGBColor) -> bool {
            self.px(x, y) == [c.0, c.1, c.2]
        }
        /// Pixels of colour `c` in the box `xs` by `ys`.
        fn count(&self, c: RGBColor, xs: Range<usize>, ys: Range<usize>) -> usize {
            ys.flat_map(|y| xs.clone().map(move |x| (x, y)))
                .filter(|&(x, y)| self.is(x, y, c))
                .count()
        }
        /// Near-black pixels (text, axes, frame) in the box `xs` by `ys`.
        fn dark(&self, xs: Range<usize>, ys: Range<usize>) -> usize {
            ys.flat_map(|y| xs.clone().map(move |x| (x, y)))
                .filter(|&(x, y)| self.px(x, y).iter().all(|&v| v < 100))
                .count()
        }
        /// The row holding the longest horizontal run of colour `c`, and that run's length.
        fn longest_run(&self, c: RGBColor) -> (usize, usize) {
            let mut best = (0, 0);
            for y in 0..self.h {
                let mut run = 0;
                for x in 0..self.w {
                    run = if self.is(x, y, c) { run + 1 } else { 0 };
                    if run > best.1 {
                        best = (y, run);
                    }
                }
            }
            best
        }
    }

    fn chart() -> Chart<'static> {
        Chart {
            title: "Cumulative geodesic error",
            x_label: "geodesic error",
            y_label: "fraction of vertices",
            x_range: (0.0, 0.25),
            y_range: (0.0, 1.0),
        }
    }

    /// Series `i` is flat at `levels[i]` over x in [0, 0.1]: the left 40% of the plot.
    fn flat_series(levels: &[f64]) -> Vec<Series> {
        levels
            .iter()
            .enumerate()
            .map(|(i, &level)| Series {
                label: format!("method {i}"),
                points: (0..=10).map(|k| (0.01 * k as f64, level)).collect(),
            })
            .collect()
    }

    /// The rows of the flat lines, checked against the y axis: each line at least 150 px
    /// long (about 270 expected), higher values higher up, equal steps in value equal
    /// steps in rows.
    fn check_lines(img: &Image, levels: &[f64]) -> Vec<usize> {
        let rows: Vec<usize> = (0..levels.len())
            .map(|i| {
                let (row, len) = img.longest_run(PALETTE[i]);
                assert!(len >= 150, "series {i}: longest run {len} px");
                row
            })
            .collect();
        assert!(rows[0] > rows[1] && rows[1] > rows[2], "rows {rows:?}");
        let mid = (rows[0] + rows[2]) as f64 / 2.0;
        assert!((rows[1] as f64 - mid).abs() <= 1.5, "rows {rows:?}");
        rows
    }

    #[test]
    fn png_has_size_distinct_series_colours_legend_and_text() {
        let levels = [0.2, 0.5, 0.8];
        let series = flat_series(&levels);
        let file = TempPng::new("lines");
        let rendered = line_chart_png(&file.0, &chart(), &series).unwrap();
        let img = Image::decode(&file.0);
        assert_eq!((img.w as u32, img.h as u32), SIZE);
        let rows = check_lines(&img, &levels);

        // Title band, and the lower-right quadrant where only the legend can be (the lines
        // are in the left 40%).
        let (w, h) = (img.w, img.h);
        let title_rows = MARGIN as usize..(MARGIN + TITLE_HEIGHT) as usize;
        let title_ink = img.dark(0..w, title_rows);
        let swatches: Vec<usize> = (0..levels.len())
            .map(|i| img.count(PALETTE[i], w / 2..w, h / 2..h))
            .collect();
        match &rendered.font {
            Some(font) => {
                assert!(font.is_file(), "{font:?}");
                assert!(title_ink > 100, "title: {title_ink} dark pixels");
                // Legend swatches: 24 px long, 2 px wide, one per series.
                assert!(swatches.iter().all(|&n| n >= 24), "{swatches:?}");
            }
            None => {
                assert_eq!(title_ink, 0);
                assert_eq!(swatches, vec![0; levels.len()]);
            }
        }

        // Without text the layout is the same: same rows, and no text or legend at all.
        let rgb = render(&chart(), &series, false).unwrap();
        let bare = Image { w, h, rgb };
        assert_eq!(check_lines(&bare, &levels), rows);
        assert_eq!(bare.dark(0..w, 0..(MARGIN + TITLE_HEIGHT) as usize), 0);
        assert!((0..levels.len()).all(|i| bare.count(PALETTE[i], w / 2..w, h / 2..h) == 0));
    }

    #[test]
    fn lines_leaving_the_ranges_are_clipped_to_the_plotting_area() {
        // Vertical through the whole chart, and a diagonal far past the right edge.
        let series = vec![
            Series {
                label: "vertical".into(),
                points: vec![(0.1, -2.0), (0.1, 3.0)],
            },
            Series {
                label: "diagonal".into(),
                points: vec![(0.0, 0.0), (1.0, 2.0)],
            },
        ];
        let rgb = render(&chart(), &series, false).unwrap();
        let img = Image {
            w: SIZE.0 as usize,
            h: SIZE.1 as usize,
            rgb,
        };
        let (w, h) = (img.w, img.h);
        let top = (MARGIN + TITLE_HEIGHT) as usize;
        let bottom = h - (MARGIN + X_LABEL_AREA) as usize;
        let right = w - (MARGIN + RIGHT_PAD) as usize;
        for c in [PALETTE[0], PALETTE[1]] {
            assert!(img.count(c, 0..w, top..bottom) > 200);
            // Nothing in the title band, the x label area or the right margin.
            assert_eq!(img.count(c, 0..w, 0..top), 0);
            assert_eq!(img.count(c, 0..w, bottom + 2..h), 0);
            assert_eq!(img.count(c, right + 2..w, 0..h), 0);
        }
    }

    #[test]
    fn clip_segment_keeps_inside_cuts_crossing_drops_outside() {
        let (x, y) = (0.0..1.0, 0.0..1.0);
        let inside = ((0.2, 0.3), (0.8, 0.9));
        assert_eq!(clip_segment(inside.0, inside.1, &x, &y), Some(inside));
        assert_eq!(
            clip_segment((-1.0, 0.5), (2.0, 0.5), &x, &y),
            Some(((0.0, 0.5), (1.0, 0.5)))
        );
        assert_eq!(
            clip_segment((0.5, 0.5), (1.5, 1.5), &x, &y),
            Some(((0.5, 0.5), (1.0, 1.0)))
        );
        assert_eq!(clip_segment((1.5, 0.0), (2.5, 1.0), &x, &y), None);
        assert_eq!(clip_segment((-1.0, 0.5), (0.5, 2.0), &x, &y), None);
        // In, out, in: two parts.
        let parts = clip_polyline(&[(0.5, 0.5), (0.5, 1.5), (0.6, 0.5)], &x, &y);
        assert_eq!(parts.len(), 2, "{parts:?}");
        assert_eq!(parts[0], vec![(0.5, 0.5), (0.5, 1.0)]);
    }

    #[test]
    fn bad_input_is_rejected_and_writes_no_file() {
        let file = TempPng::new("rejected");
        let ok = flat_series(&[0.5]);
        let mut empty_range = chart();
        empty_range.x_range = (0.25, 0.25);
        let mut nan_range = chart();
        nan_range.y_range = (0.0, f64::NAN);
        let mut nan_point = flat_series(&[0.5]);
        nan_point[0].points[3].1 = f64::NAN;
        let too_many = flat_series(&[0.5; PALETTE.len() + 1]);
        for (chart, series, name) in [
            (empty_range, &ok, "x_range"),
            (nan_range, &ok, "y_range"),
            (chart(), &nan_point, "series"),
            (chart(), &too_many, "series"),
        ] {
            match line_chart_png(&file.0, &chart, series) {
                Err(Error::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
                other => panic!("{name}: expected InvalidParameter, got {other:?}"),
            }
            assert!(!file.0.exists());
        }
        // A folder that does not exist: a file error naming the path.
        let missing = std::env::temp_dir().join("shapecorr-no-such-dir/x.png");
        match line_chart_png(&missing, &chart(), &ok) {
            Err(Error::File { path, .. }) => assert_eq!(path, missing),
            other => panic!("expected a file error, got {other:?}"),
        }
    }
}
