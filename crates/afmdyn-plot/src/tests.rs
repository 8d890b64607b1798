//! The plots' rules: dotted lines, SI axes, ticks, padding, decimation, legends.

use super::*;

/// Issue 42 §4: "unstable branch (dotted)" was drawn as a solid run of dots. A Dotted
/// series is a broken line: along the row it is drawn on, its colour alternates with the
/// background (a Line's does not).
#[test]
fn a_dotted_series_is_drawn_broken() {
    let gaps = |style: Style| {
        let fig = Figure {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            series: vec![
                Series {
                    label: String::new(),
                    points: (0..=100).map(|i| (f64::from(i) / 100.0, 0.5)).collect(),
                    style,
                    color: 3,
                },
                Series {
                    label: String::new(),
                    points: vec![(0.0, 0.0), (1.0, 1.0)],
                    style: Style::Points,
                    color: 0,
                },
            ],
            shade: vec![],
            y_min_span: 0.0,
        };
        register_font();
        let (w, h) = (600usize, 400usize);
        let mut buf = vec![255u8; w * h * 3];
        {
            let root =
                BitMapBackend::with_buffer(&mut buf, (w as u32, h as u32)).into_drawing_area();
            fig.paint(root, true).unwrap();
        }
        let c = color(3);
        let is_c = |x: usize, y: usize| {
            let i = 3 * (y * w + x);
            (buf[i], buf[i + 1], buf[i + 2]) == (c.0, c.1, c.2)
        };
        // the row with the most pixels of the series' colour, and its runs of that colour
        let row = (0..h)
            .max_by_key(|&y| (0..w).filter(|&x| is_c(x, y)).count())
            .unwrap();
        let on: Vec<bool> = (0..w).map(|x| is_c(x, row)).collect();
        assert!(
            on.iter().filter(|&&b| b).count() > 50,
            "the series is drawn"
        );
        on.windows(2).filter(|p| p[0] && !p[1]).count()
    };
    assert!(gaps(Style::Line) <= 1);
    assert!(gaps(Style::Dotted) >= 20, "{}", gaps(Style::Dotted));
}

/// SI axes take the prefix of their magnitude; other labels are left alone.
#[test]
fn si_axes_take_the_prefix_of_their_magnitude() {
    let (d, f) = si_axis("rest distance z_c (m)", 1e-9, 1.2e-8);
    assert_eq!(d, "rest distance z_c (nm)");
    assert!((f - 1e-9).abs() < 1e-24);
    assert_eq!(
        si_axis("drive frequency (Hz)", 2.9e5, 3.1e5).0,
        "drive frequency (kHz)"
    );
    assert_eq!(si_axis("virial (J)", -2.5e-18, 2.5e-18).0, "virial (aJ)");
    assert_eq!(
        si_axis("amplitude A/A0", 0.0, 1.0),
        ("amplitude A/A0".into(), 1.0)
    );
    assert_eq!(
        si_axis("phase (deg)", 0.0, 90.0),
        ("phase (deg)".into(), 1.0)
    );
    assert_eq!(si_axis("W(1,τ) (g0)", -1.0, 1.0).1, 1.0);
}

/// An axis has as many ticks at 1e-18 as at 1 (plotters alone gives one below 2.2e-16).
#[test]
fn ticks_do_not_depend_on_the_scale() {
    let unit = Axis::new(1.0, 3.0).key_points(10);
    assert!(unit.len() >= 5, "{unit:?}");
    for scale in [1e-18, 1e-9, 1e5] {
        let k = Axis::new(scale, 3.0 * scale).key_points(10);
        assert_eq!(k.len(), unit.len(), "{scale}: {k:?}");
        for (a, b) in k.iter().zip(&unit) {
            assert!((a / scale - b).abs() < 1e-9, "{scale}: {k:?}");
        }
    }
}

#[test]
fn ticks_of_one_axis_share_one_notation() {
    let span = 0.0044;
    let labels: Vec<String> = [0.0015, 0.001, 0.0005, -0.002, 0.0]
        .iter()
        .map(|v| tick(*v, span))
        .collect();
    assert_eq!(labels, ["0.0015", "0.001", "0.0005", "-0.002", "0"]);
    assert_eq!(tick(2.5, 10.0), "2.5");
    assert_eq!(tick(1200.0, 4000.0), "1200");
    assert_eq!(tick(2e-9, 4e-9), "2.00e-9");
    assert_eq!(tick(3e5, 1e6), "3.00e5");
}

/// A figure's y_min_span widens an axis whose data vary by less (round-off around zero
/// drawn as the zero it is), centred on the data; wider data keep their own range.
#[test]
fn the_y_axis_is_at_least_y_min_span_wide() {
    let fig = |ys: &[f64], span: f64| Figure {
        y_min_span: span,
        title: String::new(),
        x_label: String::new(),
        y_label: String::new(),
        series: vec![Series {
            label: String::new(),
            points: ys.iter().enumerate().map(|(i, y)| (i as f64, *y)).collect(),
            style: Style::Line,
            color: 0,
        }],
        shade: vec![],
    };
    let (_, _, y0, y1) = bounds(&fig(&[1e-27, -2e-27, 5e-28], 4e-21));
    assert!(
        y0 < -2e-21 && y1 > 2e-21 && (y0 + y1).abs() < 1e-22,
        "{y0} {y1}"
    );
    let (_, _, y0, y1) = bounds(&fig(&[1e-18, 3e-18], 4e-21));
    assert!(y0 > 0.9e-18 && y1 < 3.1e-18, "{y0} {y1}");
}

/// The padded range is the data's extent ± `frac` of it at any magnitude (SI energies of
/// 1e-18 J included), and a single value gets a range of its own magnitude's order.
#[test]
fn padding_is_relative_to_the_data() {
    for (lo, hi) in [(1e-18, 3e-18), (-2e-9, -1e-9), (0.0, 1.0), (1e5, 3e5)] {
        let (_, _, y0, y1) = padded((0.0, 1.0, lo, hi), 0.05);
        let d = hi - lo;
        assert!((y0 - (lo - 0.05 * d)).abs() <= 1e-12 * d, "{lo} {hi}: {y0}");
        assert!((y1 - (hi + 0.05 * d)).abs() <= 1e-12 * d, "{lo} {hi}: {y1}");
    }
    let (_, _, y0, y1) = padded((0.0, 1.0, 2e-18, 2e-18), 0.05);
    assert!(y0 < 2e-18 && y1 > 2e-18 && y1 - y0 < 1e-20, "{y0} {y1}");
    let (_, _, y0, y1) = padded((0.0, 1.0, 0.0, 0.0), 0.05);
    assert_eq!((y0, y1), (-0.05, 0.05));
}

#[test]
fn monotone_line_keeps_first_min_max_last_per_column() {
    let pts: Vec<(f64, f64)> = (0..100_000)
        .map(|i| {
            let x = i as f64 / 100_000.0;
            (x, (x * 5000.0).sin())
        })
        .collect();
    let runs = decimate_line(&pts, |x, y| ((x * 800.0) as i32, (y * 300.0) as i32));
    assert_eq!(runs.len(), 1);
    let n = runs[0].len();
    assert!((2 * 800..=4 * 801).contains(&n), "{n} points");
    // the envelope is kept: extremes of every column survive
    let max = runs[0].iter().map(|p| p.1).fold(f64::MIN, f64::max);
    assert_eq!(max, pts.iter().map(|p| p.1).fold(f64::MIN, f64::max));
    assert!(runs[0].windows(2).all(|w| w[0].0 <= w[1].0), "order kept");
}

#[test]
fn closed_orbit_drawn_many_times_is_drawn_once() {
    let pts: Vec<(f64, f64)> = (0..200_000)
        .map(|i| {
            let t = i as f64 * std::f64::consts::TAU / 500.0;
            (t.cos(), t.sin())
        })
        .collect();
    let n: usize = decimate_line(&pts, |x, y| ((x * 300.0) as i32, (y * 300.0) as i32))
        .iter()
        .map(Vec::len)
        .sum();
    assert!(n < 2000, "{n} points kept of 200000");
}

#[test]
fn thick_spiky_lines_stay_inside_the_data_area() {
    // a spectrum-like series: zero with tall one-sample spikes; thick polylines drew miter
    // spikes far below the x axis, through the tick labels
    let points: Vec<(f64, f64)> = (0..4000)
        .map(|k| (k as f64, if k % 97 == 0 { 1.0 } else { 0.0 }))
        .collect();
    let fig = Figure {
        y_min_span: 0.0,
        title: "spikes".into(),
        x_label: "x".into(),
        y_label: "y".into(),
        series: vec![Series {
            label: String::new(),
            points,
            style: Style::Line,
            color: 0,
        }],
        shade: vec![],
    };
    register_font();
    let (w, h) = (1000u32, 650u32);
    let bytes = png((w, h), &fig).unwrap();
    let img = image::load_from_memory(&bytes).unwrap().to_rgb8();
    let blue = color(0);
    // the x-axis label band: below the axis (margin 12 + label area 45 at the bottom)
    let stray = (h - 45..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let p = img.get_pixel(x, y);
            (p[0], p[1], p[2]) == (blue.0, blue.1, blue.2)
        })
        .count();
    assert_eq!(stray, 0, "series pixels below the x axis");
}

#[test]
fn legend_labels_wrap() {
    let w = wrap("period-1 branch (solid stable, dashed unstable)");
    assert!(
        w.len() == 2 && w.iter().all(|l| l.chars().count() <= 26),
        "{w:?}"
    );
}

/// Issue 60 item 18: an AFM image follows the instrument's habit — the colour map is dark for
/// low values and monotone in lightness (Rec. 601 luma of matplotlib's `afmhot`).
#[test]
fn the_afm_colour_map_is_dark_for_low_values() {
    let luma =
        |c: RGBColor| 0.299 * f64::from(c.0) + 0.587 * f64::from(c.1) + 0.114 * f64::from(c.2);
    assert_eq!(afmhot(0.0), RGBColor(0, 0, 0));
    assert_eq!(afmhot(1.0), RGBColor(255, 255, 255));
    let l: Vec<f64> = (0..=100)
        .map(|k| luma(afmhot(f64::from(k) / 100.0)))
        .collect();
    assert!(l.windows(2).all(|w| w[1] > w[0]), "{l:?}");
}

/// An image's data area has the scan's aspect ratio, and its high line (largest y, drawn at
/// the top) is bright, its low line dark: a 2 × 3 scan of 1 µm × 0.6 µm whose lines at
/// y = 0.1, 0.3, 0.5 µm are 0, 2.5 and 5 nm high (black, afmhot(½) and white).
#[test]
fn an_afm_image_keeps_its_aspect_and_draws_high_bright() {
    let (x, y) = ([0.25e-6, 0.75e-6], [0.1e-6, 0.3e-6, 0.5e-6]);
    let values = [0.0, 0.0, 2.5e-9, 2.5e-9, 5e-9, 5e-9];
    let map = AfmImage {
        title: "t".into(),
        x: x.to_vec(),
        y: y.to_vec(),
        values: values.to_vec(),
        label: "height (m)".into(),
    };
    let (w, h) = map.canvas();
    register_font();
    let img = image::load_from_memory(&png((w, h), &map).unwrap())
        .unwrap()
        .to_rgb8();
    // the middle line's band, in the colour no axis or text has
    let mid = afmhot(0.5);
    let (mut x0, mut x1, mut y0, mut y1) = (u32::MAX, 0, u32::MAX, 0);
    for py in 0..h {
        for px in 0..w - 190 {
            if img.get_pixel(px, py).0 == [mid.0, mid.1, mid.2] {
                (x0, x1, y0, y1) = (x0.min(px), x1.max(px), y0.min(py), y1.max(py));
            }
        }
    }
    let (band_w, band_h) = (f64::from(x1 - x0 + 1), f64::from(y1 - y0 + 1));
    // the band spans 0.2 µm of y over 1 µm of x, to a few pixels of 700
    assert!((band_h / band_w - 0.2).abs() < 0.01, "{band_h} / {band_w}");
    // above it the high line (white), below it the low one (black)
    let cx = (x0 + x1) / 2;
    assert_eq!(img.get_pixel(cx, y0 - 10).0, [255, 255, 255]);
    assert_eq!(img.get_pixel(cx, y1 + 10).0, [0, 0, 0]);
}
