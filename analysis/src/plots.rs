//! The report's figures as SVG strings, drawn with plotters' SVG backend. Without the `ttf`
//! feature plotters lays text out with a fixed-width estimate and the SVG backend writes it as
//! `<text>` elements with a generic font family, so labels need no font files and the browser
//! renders them with whatever sans-serif font it has.

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use solver::porosity::ProfilePoint;
use thiserror::Error;

use crate::correlation::CorrelationMatrix;
use crate::form_factors::symbol;

#[derive(Debug, Error, PartialEq)]
#[error("drawing the {figure}: {message}")]
pub struct PlotError {
    pub figure: &'static str,
    pub message: String,
}

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;
type Drawn = Result<(), DrawingAreaErrorKind<std::io::Error>>;

const FONT: &str = "sans-serif";
const ORANGE: RGBColor = RGBColor(230, 120, 20);
const STEEL: RGBColor = RGBColor(40, 90, 170);

/// Renders one figure into an SVG document string.
fn render(figure: &'static str, size: (u32, u32), draw: impl FnOnce(&Area) -> Drawn) -> Result<String, PlotError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let result = root.fill(&WHITE).and_then(|_| draw(&root)).and_then(|_| root.present());
        result.map_err(|e| PlotError { figure, message: e.to_string() })?;
    }
    Ok(svg)
}

/// A chart over x and y with the report's margins and a caption of `size` points.
fn chart<'a, 'b>(
    area: &'a Area<'b>,
    caption: &str,
    size: u32,
    x: (f64, f64),
    y: (f64, f64),
) -> Result<Chart<'a, 'b>, DrawingAreaErrorKind<std::io::Error>> {
    ChartBuilder::on(area)
        .caption(caption, (FONT, size))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
}

/// Axes in the report's style: described, ticks with as many decimals as the ranges need, a
/// white grid.
fn axes(chart: &mut Chart, x_desc: &str, y_desc: &str, x: (f64, f64), y: (f64, f64)) -> Drawn {
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 15))
        .x_label_formatter(&|v| format!("{v:.*}", decimals(x)))
        .y_label_formatter(&|v| format!("{v:.*}", decimals(y)))
        .light_line_style(WHITE)
        .draw()
}

/// The series' legend in `corner` of the plot, on a translucent white box.
fn legend<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>, font: u32, corner: Corner) -> Drawn {
    let position = match corner {
        Corner::UpperLeft => SeriesLabelPosition::UpperLeft,
        Corner::UpperRight => SeriesLabelPosition::UpperRight,
        Corner::LowerLeft => SeriesLabelPosition::LowerLeft,
        Corner::LowerRight => SeriesLabelPosition::LowerRight,
    };
    chart
        .configure_series_labels()
        .position(position)
        .label_font((FONT, font))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .draw()
}

/// A corner of a plot, for its legend.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Corner {
    UpperLeft,
    UpperRight,
    LowerLeft,
    LowerRight,
}

/// The corner whose box of half the width and a third of the height (about a legend of a few
/// lines) holds the fewest of `points`, upper left first among equals.
fn emptiest_corner(points: &[(f64, f64)], x: (f64, f64), y: (f64, f64)) -> Corner {
    let middle = 0.5 * (x.0 + x.1);
    let (low, high) = (y.0 + (y.1 - y.0) / 3.0, y.1 - (y.1 - y.0) / 3.0);
    let count = |inside: &dyn Fn(f64, f64) -> bool| points.iter().filter(|p| inside(p.0, p.1)).count();
    [
        (Corner::UpperLeft, count(&|px, py| px <= middle && py >= high)),
        (Corner::UpperRight, count(&|px, py| px >= middle && py >= high)),
        (Corner::LowerLeft, count(&|px, py| px <= middle && py <= low)),
        (Corner::LowerRight, count(&|px, py| px >= middle && py <= low)),
    ]
    .into_iter()
    .min_by_key(|c| c.1)
    .expect("four corners")
    .0
}

/// [min, max] of finite values widened by 5 % (or ±0.5 % of the value for a single value),
/// so points do not sit on the frame.
fn padded_range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { 0.005 * lo.abs().max(1e-3) };
    (lo - pad, hi + pad)
}

/// Decimals that tell ticks apart on an axis spanning `range`: one more than the range's
/// leading digit needs.
fn decimals(range: (f64, f64)) -> usize {
    let span = (range.1 - range.0).abs();
    if span > 0.0 { (1 - span.log10().floor() as i32).max(0) as usize } else { 3 }
}

/// One packing's number-based mean and std of elongation and flatness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZinggPacking {
    pub mean_el: f64,
    pub std_el: f64,
    pub mean_fl: f64,
    pub std_fl: f64,
}

impl ZinggPacking {
    /// Whether its ellipse shows: a semi-axis of σ ≥ 0.002 is a pixel or more of the diagram's
    /// ~480 px axes (a single-form packing's σ is zero up to rounding).
    pub fn has_spread(&self) -> bool {
        self.std_el.max(self.std_fl) >= 0.002
    }
}

/// Zingg diagram like Fig. 11: EL on x, FL on y, the class boundaries at 2/3, each packing's
/// mean as a point and its standard deviations as the semi-axes of an ellipse.
pub fn zingg_diagram(packings: &[ZinggPacking]) -> Result<String, PlotError> {
    render("Zingg diagram", (620, 600), |root| {
        // The legend gets its own strip below the chart: inside, it would hide packings.
        let (upper, lower) = root.split_vertically(560);
        let mut chart = ChartBuilder::on(&upper)
            .caption("Zingg diagram of the packings", (FONT, 20))
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(60)
            .build_cartesian_2d(0f64..1f64, 0f64..1f64)?;
        chart
            .configure_mesh()
            .x_desc("elongation EL = I/L (–)")
            .y_desc("flatness FL = S/I (–)")
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 15))
            .x_labels(6)
            .y_labels(6)
            .light_line_style(WHITE)
            .draw()?;
        let boundary = BLACK.mix(0.6).stroke_width(1);
        chart.draw_series(DashedLineSeries::new([(2.0 / 3.0, 0.0), (2.0 / 3.0, 1.0)], 6, 4, boundary))?;
        chart.draw_series(DashedLineSeries::new([(0.0, 2.0 / 3.0), (1.0, 2.0 / 3.0)], 6, 4, boundary))?;
        let class_style =
            TextStyle::from((FONT, 15).into_font()).color(&BLACK).pos(Pos::new(HPos::Center, VPos::Center));
        for (name, at) in [
            ("rod", (1.0 / 3.0, 0.97)),
            ("equant", (5.0 / 6.0, 0.97)),
            ("blade", (1.0 / 3.0, 0.03)),
            ("disk", (5.0 / 6.0, 0.03)),
        ] {
            chart.draw_series(std::iter::once(Text::new(name, at, class_style.clone())))?;
        }
        let ellipse = |p: &ZinggPacking| -> Vec<(f64, f64)> {
            (0..=48)
                .map(|k| {
                    let t = std::f64::consts::TAU * k as f64 / 48.0;
                    (p.mean_el + p.std_el * t.cos(), p.mean_fl + p.std_fl * t.sin())
                })
                .collect()
        };
        let spread: Vec<&ZinggPacking> = packings.iter().filter(|p| p.has_spread()).collect();
        chart.draw_series(spread.iter().map(|p| PathElement::new(ellipse(p), STEEL.mix(0.7).stroke_width(1))))?;
        chart.draw_series(packings.iter().map(|p| Circle::new((p.mean_el, p.mean_fl), 4, ORANGE.filled())))?;
        let left = TextStyle::from((FONT, 13).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
        lower.draw(&Circle::new((90, 18), 4, ORANGE.filled()))?;
        lower.draw(&Text::new("packing mean (μ_EL, μ_FL)", (100, 18), left.clone()))?;
        if !spread.is_empty() {
            lower.draw(&Circle::new((330, 18), 7, STEEL.stroke_width(1)))?;
            lower.draw(&Text::new("standard deviations as semi-axes", (343, 18), left))?;
        }
        Ok(())
    })
}

/// Points and, optionally, a straight line with its legend (Fig. 8: porosity against the
/// primary feature with the implied linear model).
pub struct ScatterPlot<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub points: &'a [(f64, f64)],
    /// (slope, intercept, legend) of the line.
    pub line: Option<(f64, f64, String)>,
}

pub fn scatter(plot: &ScatterPlot) -> Result<String, PlotError> {
    render("scatter plot", (640, 480), |root| {
        let x = padded_range(plot.points.iter().map(|p| p.0));
        let y = padded_range(plot.points.iter().map(|p| p.1));
        let mut chart = chart(root, plot.title, 19, x, y)?;
        axes(&mut chart, plot.x_label, plot.y_label, x, y)?;
        chart
            .draw_series(plot.points.iter().map(|&p| Circle::new(p, 4, STEEL.filled())))?
            .label("packings")
            .legend(|(x, y)| Circle::new((x + 7, y), 4, STEEL.filled()));
        if let Some((slope, intercept, legend)) = &plot.line {
            let line = [(x.0, intercept + slope * x.0), (x.1, intercept + slope * x.1)];
            chart
                .draw_series(LineSeries::new(line, RED.stroke_width(2)))?
                .label(legend.as_str())
                .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], RED.stroke_width(2)));
        }
        legend(&mut chart, 13, emptiest_corner(plot.points, x, y))
    })
}

/// One series of [`series_with_spread`]: a label and its points (x, mean y, std of y).
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64, f64)>,
    /// A model's curve rather than measurements: drawn dashed, without markers.
    pub model: bool,
}

/// Series of means joined in order of x, each point with a bar of ± one standard deviation
/// (Fig. 10: porosity against the inverse equancy, one series per grain shape).
pub fn series_with_spread(title: &str, x_label: &str, y_label: &str, series: &[Series]) -> Result<String, PlotError> {
    render("series plot", (640, 480), |root| {
        let all = || series.iter().flat_map(|s| s.points.iter());
        let x = padded_range(all().map(|p| p.0));
        let y = padded_range(all().flat_map(|p| [p.1 - p.2, p.1 + p.2]));
        // Headroom for the legend (upper left: its frame and one line per series) so that it
        // hides no point.
        let y = (y.0, y.1 + (y.1 - y.0) * (0.08 + 0.07 * series.len() as f64));
        let mut chart = chart(root, title, 19, x, y)?;
        axes(&mut chart, x_label, y_label, x, y)?;
        for (k, s) in series.iter().enumerate() {
            let colour = match k {
                0 => STEEL,
                1 => ORANGE,
                2 => RGBColor(40, 150, 70),
                _ => {
                    let (r, g, b) = Palette99::pick(k).rgb();
                    RGBColor(r, g, b)
                }
            };
            let mut points = s.points.clone();
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            if s.model {
                let line = points.iter().map(|p| (p.0, p.1));
                chart
                    .draw_series(DashedLineSeries::new(line, 6, 4, colour.stroke_width(2)))?
                    .label(s.label.as_str())
                    .legend(move |(x, y)| DashedPathElement::new([(x, y), (x + 16, y)], 6, 4, colour.stroke_width(2)));
                continue;
            }
            chart.draw_series(LineSeries::new(points.iter().map(|p| (p.0, p.1)), colour.stroke_width(1)))?;
            chart.draw_series(
                points
                    .iter()
                    .filter(|p| p.2 > 0.0)
                    .map(|p| ErrorBar::new_vertical(p.0, p.1 - p.2, p.1, p.1 + p.2, colour.stroke_width(1), 6)),
            )?;
            chart
                .draw_series(points.iter().map(|p| Circle::new((p.0, p.1), 4, colour.filled())))?
                .label(s.label.as_str())
                .legend(move |(x, y)| Circle::new((x + 7, y), 4, colour.filled()));
        }
        legend(&mut chart, 13, Corner::UpperLeft)
    })
}

/// Predicted against observed porosity with the 1:1 line (Figs. 9 and 12): the model fitted on
/// all rows, and each row's held-out cross-validation prediction.
pub fn predicted_vs_observed(
    title: &str,
    observed: &[f64],
    fitted: &[f64],
    held_out: &[f64],
) -> Result<String, PlotError> {
    render("predicted-versus-observed plot", (560, 540), |root| {
        let (lo, hi) = padded_range(observed.iter().chain(fitted).chain(held_out).copied());
        let mut chart = chart(root, title, 18, (lo, hi), (lo, hi))?;
        axes(&mut chart, "observed porosity n (–)", "predicted porosity n (–)", (lo, hi), (lo, hi))?;
        chart
            .draw_series(LineSeries::new([(lo, lo), (hi, hi)], BLACK.stroke_width(1)))?
            .label("perfect agreement")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK.stroke_width(1)));
        chart
            .draw_series(observed.iter().zip(held_out).map(|(&o, &p)| Circle::new((o, p), 4, RED.stroke_width(1))))?
            .label("held-out (cross-validation)")
            .legend(|(x, y)| Circle::new((x + 7, y), 4, RED.stroke_width(1)));
        chart
            .draw_series(observed.iter().zip(fitted).map(|(&o, &p)| Circle::new((o, p), 3, STEEL.filled())))?
            .label("fitted on all packings")
            .legend(|(x, y)| Circle::new((x + 7, y), 3, STEEL.filled()));
        let points: Vec<(f64, f64)> =
            observed.iter().zip(fitted).chain(observed.iter().zip(held_out)).map(|(&o, &p)| (o, p)).collect();
        legend(&mut chart, 13, emptiest_corner(&points, (lo, hi), (lo, hi)))
    })
}

/// Diverging colour for r ∈ [−1, 1]: blue for negative, white at 0, red for positive.
fn correlation_colour(r: f64) -> RGBColor {
    let t = r.clamp(-1.0, 1.0).abs();
    let mix = |full: u8| (255.0 + (full as f64 - 255.0) * t).round() as u8;
    if r >= 0.0 { RGBColor(mix(200), mix(40), mix(40)) } else { RGBColor(mix(40), mix(80), mix(200)) }
}

/// The correlation matrix as a heat map with the value of r in each cell (Fig. 3).
pub fn heat_map(title: &str, matrix: &CorrelationMatrix) -> Result<String, PlotError> {
    const CELL: i32 = 50;
    const LEFT: i32 = 110;
    const TOP: i32 = 90;
    let n = matrix.features.len() as i32;
    let size = ((LEFT + n * CELL + 90) as u32, (TOP + n * CELL + 20) as u32);
    render("correlation matrix", size, |root| {
        let centred = |px: i32| TextStyle::from((FONT, px).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
        root.draw(&Text::new(title.to_string(), (size.0 as i32 / 2, 22), centred(19)))?;
        let labels: Vec<String> = matrix.features.iter().map(|f| symbol(f)).collect();
        for (k, label) in labels.iter().enumerate() {
            let k = k as i32;
            let right = TextStyle::from((FONT, 13).into_font()).pos(Pos::new(HPos::Right, VPos::Center));
            root.draw(&Text::new(label.clone(), (LEFT - 8, TOP + k * CELL + CELL / 2), right))?;
            let up = TextStyle::from((FONT, 13).into_font())
                .pos(Pos::new(HPos::Left, VPos::Center))
                .transform(FontTransform::Rotate270);
            root.draw(&Text::new(label.clone(), (LEFT + k * CELL + CELL / 2, TOP - 8), up))?;
        }
        for (i, row) in matrix.r.iter().enumerate() {
            for (j, r) in row.iter().enumerate() {
                let (x, y) = (LEFT + j as i32 * CELL, TOP + i as i32 * CELL);
                let fill = r.map_or(RGBColor(220, 220, 220), correlation_colour);
                root.draw(&Rectangle::new([(x, y), (x + CELL, y + CELL)], fill.filled()))?;
                root.draw(&Rectangle::new([(x, y), (x + CELL, y + CELL)], WHITE.stroke_width(1)))?;
                let text = r.map_or("–".to_string(), |r| format!("{r:.2}"));
                let ink = if r.is_some_and(|r| r.abs() > 0.6) { WHITE } else { BLACK };
                root.draw(&Text::new(text, (x + CELL / 2, y + CELL / 2), centred(12).color(&ink)))?;
            }
        }
        // Colour bar from r = 1 (top) to r = −1 (bottom).
        let bar_x = LEFT + n * CELL + 25;
        let bar_h = n * CELL;
        for step in 0..bar_h {
            let r = 1.0 - 2.0 * step as f64 / bar_h as f64;
            root.draw(&Rectangle::new(
                [(bar_x, TOP + step), (bar_x + 16, TOP + step + 1)],
                correlation_colour(r).filled(),
            ))?;
        }
        let left = TextStyle::from((FONT, 12).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
        for (r, at) in [("1", 0), ("0", bar_h / 2), ("−1", bar_h)] {
            root.draw(&Text::new(r.to_string(), (bar_x + 21, TOP + at), left.clone()))?;
        }
        root.draw(&Text::new("r".to_string(), (bar_x + 8, TOP - 12), centred(14)))?;
        Ok(())
    })
}

/// Porosity profiles n(z) of the packings, height upwards as in a bed.
pub fn profiles(profiles: &[(String, Vec<ProfilePoint>)]) -> Result<String, PlotError> {
    render("porosity profiles", (640, 520), |root| {
        let top = padded_range(profiles.iter().flat_map(|(_, p)| p.iter().map(|q| q.z))).1.max(1e-3);
        let mut chart = chart(root, "Porosity profiles n(z)", 19, (0.0, 1.0), (0.0, top))?;
        axes(&mut chart, "slice porosity n (–)", "height z (m)", (0.0, 1.0), (0.0, top))?;
        // A legend for a handful of packings helps; for a campaign it would hide the plot.
        let with_legend = profiles.len() <= 8;
        for (k, (label, points)) in profiles.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            let series =
                chart.draw_series(LineSeries::new(points.iter().map(|p| (p.n, p.z)), colour.stroke_width(1)))?;
            if with_legend {
                series
                    .label(label.as_str())
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(2)));
            }
        }
        if with_legend {
            legend(&mut chart, 12, Corner::UpperLeft)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_padded_and_survive_degenerate_data() {
        assert_eq!(padded_range([1.0, 3.0]), (0.9, 3.1));
        let (lo, hi) = padded_range([0.3, 0.3]);
        assert!(lo < 0.3 && hi > 0.3);
        assert_eq!(padded_range([f64::NAN]), (0.0, 1.0));
    }

    #[test]
    fn tick_decimals_follow_the_span() {
        assert_eq!(decimals((1.3, 5.2)), 1);
        assert_eq!(decimals((0.34, 0.47)), 2);
        assert_eq!(decimals((0.0, 0.03)), 3);
        assert_eq!(decimals((100.0, 900.0)), 0);
    }

    #[test]
    fn a_model_series_is_a_dashed_line_without_markers() {
        let series = |model| Series { label: "s".into(), points: vec![(1.0, 0.3, 0.01), (2.0, 0.4, 0.0)], model };
        let measured = series_with_spread("t", "x", "y", &[series(false)]).unwrap();
        let model = series_with_spread("t", "x", "y", &[series(true)]).unwrap();
        // The first series' colour, as the SVG writes it.
        let (stroke, fill) = ("stroke=\"#285AAA\"", "fill=\"#285AAA\"");
        let elements = |svg: &str, tag: &str, attribute: &str| {
            svg.split('<').filter(|e| e.starts_with(tag) && e.contains(attribute)).count()
        };
        // Markers: one filled circle per point and one in the legend.
        assert_eq!(elements(&measured, "circle", fill), 3, "{measured}");
        assert_eq!(elements(&model, "circle", fill), 0, "{model}");
        // The line joining the points: one polyline, or a dash every 10 px of the ~550 px between
        // the two points.
        assert_eq!(elements(&measured, "polyline", stroke), 1, "{measured}");
        assert!(elements(&model, "polyline", stroke) > 30, "{model}");
        // The legend's symbol, the only horizontal stroke (the curve rises): dashed like the
        // curve, so more than one piece, each shorter than the 16 px of a solid symbol.
        let horizontal: Vec<i32> = model
            .split('<')
            .filter(|e| e.starts_with("polyline") && e.contains(stroke))
            .filter_map(|e| {
                let points = e.split("points=\"").nth(1)?.split('"').next()?;
                let xy: Vec<(i32, i32)> = points
                    .split_whitespace()
                    .filter_map(|p| p.split_once(',').map(|(x, y)| (x.parse().unwrap(), y.parse().unwrap())))
                    .collect();
                let (first, last) = (xy.first()?, xy.last()?);
                (first.1 == last.1).then_some(last.0 - first.0)
            })
            .collect();
        assert!(horizontal.len() > 1 && horizontal.iter().all(|&l| l < 16), "{horizontal:?}");
    }

    #[test]
    fn a_zingg_diagram_draws_ellipses_and_their_legend_only_for_packings_with_a_spread() {
        let single = ZinggPacking { mean_el: 0.53, std_el: 1e-17, mean_fl: 0.53, std_fl: 0.0 };
        let mixture = ZinggPacking { mean_el: 0.68, std_el: 0.14, mean_fl: 0.65, std_fl: 0.17 };
        let ellipses =
            |svg: &str| svg.split('<').filter(|e| e.starts_with("polyline") && e.contains("#285AAA")).count();
        let one_form = zingg_diagram(&[single, single]).unwrap();
        assert_eq!(ellipses(&one_form), 0, "{one_form}");
        assert!(!one_form.contains("standard deviations"), "{one_form}");
        let both = zingg_diagram(&[single, mixture]).unwrap();
        assert_eq!(ellipses(&both), 1, "{both}");
        assert!(both.contains("standard deviations as semi-axes"), "{both}");
    }

    #[test]
    fn the_legend_goes_where_it_hides_fewest_points() {
        let (x, y) = ((0.0, 1.0), (0.0, 1.0));
        // A falling line of points (Fig. 8 with r < 0) fills the upper left and lower right.
        let falling: Vec<(f64, f64)> = (0..=10).map(|k| (0.1 * k as f64, 1.0 - 0.1 * k as f64)).collect();
        assert_eq!(emptiest_corner(&falling, x, y), Corner::UpperRight);
        // A rising one (Figs. 9 and 12, on the 1:1 line) leaves the upper left free.
        let rising: Vec<(f64, f64)> = falling.iter().map(|p| (p.0, 1.0 - p.1)).collect();
        assert_eq!(emptiest_corner(&rising, x, y), Corner::UpperLeft);
        // Points everywhere but the lower left.
        let spread = [(0.1, 0.9), (0.9, 0.9), (0.9, 0.1), (0.2, 0.8), (0.8, 0.2), (0.8, 0.8)];
        assert_eq!(emptiest_corner(&spread, x, y), Corner::LowerLeft);
    }

    #[test]
    fn correlation_colours_run_blue_white_red() {
        assert_eq!(correlation_colour(0.0), RGBColor(255, 255, 255));
        assert_eq!(correlation_colour(1.0), RGBColor(200, 40, 40));
        assert_eq!(correlation_colour(-1.0), RGBColor(40, 80, 200));
    }
}
