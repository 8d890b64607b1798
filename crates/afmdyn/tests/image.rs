//! Ideal-feedback images (issue 46, [`afmdyn::request::image`]): every domain of a line
//! PS | rubber | PS | step shows the operating point `approach --setpoint` finds on its
//! material alone (its apparent height the difference of the rest distances, its phase the
//! same); a true step of the background material shows at its true height; a line engages on
//! the approach sweep's first operating point and keeps its regime across materials where it
//! can; the sample map's refusals name their key.

use afmdyn::analysis::approach::approach_retract;
use afmdyn::probe::Probe;
use afmdyn::report::{setpoint, CurveUnits};
use afmdyn::request::curves::{approach_request, CurveRequest};
use afmdyn::request::image::{study_ratios, ImageRequest, Regime, SampleMap};
use afmdyn::study::image_ideal::{image, setpoint_study};

fn repo(path: &str) -> String {
    std::fs::read_to_string(format!("{}/../../{path}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// The probe text with its `[sample]` table replaced by `sample` (the domain's keys), written
/// out as a probe file a user would write for that material alone.
fn probe_with_sample(probe: &str, sample: &str) -> String {
    let mut out = String::new();
    let mut skip = false;
    for line in probe.lines() {
        if line.trim_start().starts_with('[') {
            skip = line.trim() == "[sample]";
            if skip {
                out.push_str("[sample]\n");
                out.push_str(sample);
                out.push('\n');
                continue;
            }
        }
        if !skip {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// `approach --setpoint r --no-branches` on one probe: its operating points (z_c, regime,
/// phase), in SI.
fn operating_points(probe_text: &str, r: f64, points: usize) -> Vec<(f64, String, f64, String)> {
    let p = Probe::parse(probe_text, "<test>").unwrap();
    let u = CurveUnits::from_scales(&p.scales, false);
    let req = CurveRequest {
        points: Some(points),
        branches: false,
        ..CurveRequest::default()
    };
    let spec = approach_request(p.params, &req, u.length, false).unwrap();
    let c = approach_retract(&spec).unwrap();
    let ops = afmdyn::analysis::setpoint::operating_points(&spec, &c, r).unwrap();
    let doc = setpoint(&p.params, &c, (&ops.0, &ops.1), r, &u);
    doc["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|q| {
            (
                q["z_c"].as_f64().unwrap(),
                q["regime"].as_str().unwrap().to_string(),
                q["phase_deg"].as_f64().unwrap(),
                q["source"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

const RUBBER: &str = "law = \"dmt\"\nyoungs_modulus = 50e6\npoisson_ratio = 0.45\nhamaker = \
                      6.6e-20\nintermolecular_distance = 0.165e-9\nviscosity = 5.0";

/// The line of `examples/sample-stripe.toml` over `examples/probe-point-mass-dmt.toml` at the
/// setpoint 0.7: the background (polystyrene) is imaged on its repulsive operating point, the
/// rubber stripe on its own attractive one (it has no other at this setpoint: a regime switch,
/// reported), the step of polystyrene 5 nm higher at exactly 5 nm; each as `approach
/// --setpoint` locates it on that material alone, from a probe file with that sample.
#[test]
fn each_domain_shows_its_own_operating_point() {
    let probe = repo("examples/probe-point-mass-dmt.toml");
    let table: toml::Table = probe.parse().unwrap();
    let map = SampleMap::parse(&repo("examples/sample-stripe.toml"), "<test>").unwrap();
    let req = ImageRequest {
        setpoint: 0.7,
        pixels: 50,
        ..ImageRequest::at(0.7)
    };
    let img = image(&table, &map, &req).unwrap();
    let bg = operating_points(&probe, 0.7, 120);
    let rubber = operating_points(&probe_with_sample(&probe, RUBBER), 0.7, 120);
    // engaged from far: the approach sweep's operating point of largest z_c
    let engaged = bg
        .iter()
        .filter(|p| p.3 == "approach")
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap();
    assert!(
        (img.reference - engaged.0).abs() < 1e-18,
        "{} vs {engaged:?}",
        img.reference
    );
    let mut seen = [false; 3];
    for (i, &x) in img.x.iter().enumerate() {
        let p = img.pixels[0][i];
        let o = img.point(0, i).unwrap();
        let h = img.apparent_height(0, i);
        match p.domain {
            None => {
                // polystyrene at the reference: height 0, the engaged phase
                assert_eq!(h, 0.0, "x = {x}");
                assert_eq!(o.phase_deg, engaged.2);
                assert_eq!(o.regime, Regime::Repulsive);
                seen[0] = true;
            }
            Some(0) => {
                // the rubber: attractive only (on both sweeps), so the line switches to the
                // operating point nearest the background's z_c; the height its z_c's
                // difference from polystyrene's
                assert!(rubber.iter().all(|p| p.1 == "attractive"), "{rubber:?}");
                let want = rubber
                    .iter()
                    .min_by(|a, b| (a.0 - engaged.0).abs().total_cmp(&(b.0 - engaged.0).abs()))
                    .unwrap();
                assert!((h - (want.0 - engaged.0)).abs() < 1e-18, "{h}");
                assert!((o.phase_deg - want.2).abs() < 1e-12);
                seen[1] = true;
            }
            Some(_) => {
                // the step: the background's point, 5 nm up
                assert!((h - 5e-9).abs() < 1e-18, "{h}");
                assert_eq!(o.phase_deg, engaged.2);
                seen[2] = true;
            }
        }
    }
    assert_eq!(seen, [true; 3]);
    // entering and leaving the stripe switch regime, and the document says so
    let switched: usize = img.pixels[0].iter().map(|p| usize::from(p.switched)).sum();
    assert_eq!(switched, 2);
    assert!(img
        .warnings
        .iter()
        .any(|w| w.contains("2 pixel(s) switch regime")));
    let doc = img.document(0.7);
    assert_eq!(doc["image"]["height"][0].as_array().unwrap().len(), 50);
    assert_eq!(doc["image"]["domain"][0][20], "rubber");
}

/// Where the setpoint has an attractive and a repulsive operating point (the RTESPA-300 over
/// polystyrene at A/A0 = 0.95, bistable), the line engages on the attractive one the approach
/// meets first, and a domain of a softer polymer that has both keeps the line attractive.
#[test]
fn a_line_engages_from_far_and_keeps_its_regime() {
    let probe = repo("examples/probe-rtespa300-polystyrene.toml");
    let bg = operating_points(&probe, 0.95, 120);
    let regimes: Vec<&str> = bg.iter().map(|p| p.1.as_str()).collect();
    assert!(
        regimes.contains(&"attractive") && regimes.contains(&"repulsive"),
        "{bg:?}"
    );
    let map = SampleMap::parse(
        "size = [1e-6, 0]\n[[domain]]\nname = \"soft\"\nx = [0.4e-6, 0.6e-6]\n\
         [domain.sample]\nlaw = \"dmt\"\nyoungs_modulus = 1e9\npoisson_ratio = 0.4\n\
         hamaker = 6.6e-20\nviscosity = 10.0\n",
        "<test>",
    )
    .unwrap();
    let req = ImageRequest {
        setpoint: 0.95,
        pixels: 20,
        ..ImageRequest::at(0.95)
    };
    let img = image(&probe.parse().unwrap(), &map, &req).unwrap();
    assert_eq!(img.point(0, 0).unwrap().regime, Regime::Attractive);
    // the softer polymer has both regimes at this setpoint too: the line stays attractive
    let soft = &img.materials[1].points;
    for r in [Regime::Attractive, Regime::Repulsive] {
        assert!(soft.iter().any(|p| p.regime == r), "{soft:?}");
    }
    for i in 0..20 {
        assert_eq!(
            img.point(0, i).unwrap().regime,
            Regime::Attractive,
            "pixel {i}"
        );
        assert!(!img.pixels[0][i].switched);
    }
}

/// A 2D map: where domains overlap the later one lies on top; the request's and the map's
/// refusals name their key.
#[test]
fn sample_maps_and_their_refusals() {
    let map = SampleMap::parse(
        "size = [1e-6, 1e-6]\n[[domain]]\nname = \"a\"\nx = [0, 0.6e-6]\n\
         [[domain]]\nname = \"b\"\nx = [0.4e-6, 1e-6]\ny = [0, 0.5e-6]\nheight = 2e-9\n",
        "<test>",
    )
    .unwrap();
    assert_eq!(map.domain_at(0.5e-6, 0.2e-6), Some(1));
    assert_eq!(map.domain_at(0.5e-6, 0.8e-6), Some(0));
    assert_eq!(map.domain_at(0.8e-6, 0.8e-6), None);
    let refused = |text: &str, key: &str| {
        let e = SampleMap::parse(text, "s.toml").unwrap_err().to_string();
        assert!(e.contains(key) && e.contains("s.toml"), "{key}: {e}");
    };
    refused("size = [1e-6]", "size");
    refused("size = [0, 0]", "size");
    refused("size = [1e-6, 0]\ncolour = 1", "colour");
    refused("size = [1e-6, 0]\n[[domain]]\nname = \"d\"", "domain 'd' x");
    refused(
        "size = [1e-6, 0]\n[[domain]]\nname = \"d\"\nx = [2e-7, 1e-7]",
        "domain 'd' x",
    );
    refused(
        "size = [1e-6, 0]\n[[domain]]\nx = [2e-6, 3e-6]",
        "outside the map",
    );
    refused(
        "size = [1e-6, 0]\n[[domain]]\nname = \"d\"\nx = [0, 1e-7]\nheight = 1e-3",
        "domain 'd' height",
    );
    refused(
        "size = [1e-6, 0]\n[[domain]]\nname = \"d\"\nx = [0, 1e-7]\n[domain.sample]\nz_c = 1e-9",
        "sample.z_c",
    );
    refused("size = [1e-6, 0", "invalid TOML");
    let line = SampleMap::parse("size = [1e-6, 0]", "<test>").unwrap();
    let req = |setpoint: f64, lines: usize| ImageRequest {
        setpoint,
        pixels: 8,
        lines: Some(lines),
        curve_points: 40,
        temperature: None,
    };
    for (r, key) in [
        (req(1.0, 1), "setpoint"),
        (req(0.0, 1), "setpoint"),
        (req(0.5, 2), "lines"),
        (
            ImageRequest {
                pixels: 0,
                ..req(0.5, 1)
            },
            "pixels",
        ),
    ] {
        let e = r.validate(&line).unwrap_err().to_string();
        assert!(e.contains(key), "{e}");
    }
    // a domain's sample that the probe format refuses is named by its domain
    let probe: toml::Table = repo("examples/probe-point-mass-dmt.toml").parse().unwrap();
    let bad = SampleMap::parse(
        "size = [1e-6, 0]\n[[domain]]\nname = \"glass\"\nx = [0, 1e-7]\n[domain.sample]\n\
         law = \"dmt\"\nyoungs_modulus = -1\npoisson_ratio = 0.2\nhamaker = 1e-20\n",
        "<test>",
    )
    .unwrap();
    let e = image(&probe, &bad, &req(0.7, 1)).unwrap_err().to_string();
    assert!(
        e.contains("domain 'glass'") && e.contains("youngs_modulus"),
        "{e}"
    );
}

/// The setpoint study is the image's operating points ratio by ratio: at each of 6 setpoints
/// every domain's apparent height and phase equal those of the stripe line imaged at that
/// setpoint (the line engages on the background and crosses onto the rubber, then the step);
/// its ratios parse from FROM:TO:N, and other forms are refused naming setpoint_study.
#[test]
fn the_setpoint_study_is_the_image_at_each_setpoint() {
    let probe: toml::Table = repo("examples/probe-point-mass-dmt.toml").parse().unwrap();
    let map = SampleMap::parse(&repo("examples/sample-stripe.toml"), "<test>").unwrap();
    let ratios = study_ratios("0.3:0.9:6").unwrap();
    assert_eq!(ratios.len(), 6);
    assert!((ratios[1] - 0.42).abs() < 1e-15 && ratios[5] == 0.9);
    let study = setpoint_study(&probe, &map, &ratios, 120).unwrap();
    let names: Vec<&str> = study.domains.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(names, ["background", "rubber", "step"]);
    for (k, &r) in ratios.iter().enumerate() {
        let img = image(
            &probe,
            &map,
            &ImageRequest {
                pixels: 40,
                ..ImageRequest::at(r)
            },
        )
        .unwrap();
        for (d, series) in study.domains.iter().enumerate() {
            let want = if d == 0 { None } else { Some(d - 1) };
            let i = img.pixels[0].iter().position(|p| p.domain == want).unwrap();
            let (h, o) = (img.apparent_height(0, i), img.point(0, i).unwrap());
            assert_eq!(series.apparent_height[k], h, "{} at {r}", series.name);
            assert_eq!(series.phase_deg[k], o.phase_deg, "{} at {r}", series.name);
            assert_eq!(series.regime[k], Some(o.regime));
        }
    }
    for bad in ["0.2:0.9", "0:0.9:5", "0.2:1.0:5", "0.2:0.9:1", "a:b:c"] {
        let e = study_ratios(bad).unwrap_err().to_string();
        assert!(e.contains("setpoint_study"), "{bad}: {e}");
    }
}

/// A smooth step (a domain's `width`) rises as the smoothstep 3t² − 2t³ of the distance to its
/// edge over the width — half its height at half the width — and a height map is interpolated
/// bilinearly (its nodes exactly, midpoints the mean); over one material the ideal feedback
/// records that true topography exactly (apparent = true height).
#[test]
fn smooth_steps_and_height_maps_are_recorded_as_they_are() {
    let map = SampleMap::parse(
        "size = [1e-6, 1e-6]\nheight_map = [[0, 1e-9, 2e-9], [4e-9, 5e-9, 6e-9]]\n\
         [[domain]]\nname = \"terrace\"\nx = [0.5e-6, 1e-6]\nheight = 4e-9\nwidth = 0.2e-6\n",
        "<test>",
    )
    .unwrap();
    let h = |x: f64, y: f64| map.height_at(x, y);
    // the height map alone left of the terrace: nodes at x = 0, 0.5 µm, 1 µm and y = 0, 1 µm
    assert_eq!(h(0.0, 0.0), 0.0);
    assert!((h(0.25e-6, 0.5e-6) - (0.5e-9 + 4.5e-9) / 2.0).abs() < 1e-20);
    // the terrace: half its height at half its width from the edge x = 0.5 µm, all of it beyond
    let step = |x: f64| h(x, 0.0) - (x / 0.5e-6) * 1e-9;
    assert!((step(0.6e-6) - 2e-9).abs() < 1e-20, "{}", step(0.6e-6));
    assert!((step(0.8e-6) - 4e-9).abs() < 1e-20);
    // the map's own edge (x = 1 µm) is no step
    assert!((step(1e-6) - 4e-9).abs() < 1e-20);
    let probe: toml::Table = repo("examples/probe-point-mass-dmt.toml").parse().unwrap();
    let img = image(
        &probe,
        &map,
        &ImageRequest {
            pixels: 10,
            lines: Some(3),
            ..ImageRequest::at(0.7)
        },
    )
    .unwrap();
    for (j, &y) in img.y.iter().enumerate() {
        for (i, &x) in img.x.iter().enumerate() {
            assert_eq!(img.pixels[j][i].height, h(x, y));
            assert!((img.apparent_height(j, i) - h(x, y)).abs() < 1e-20);
        }
    }
    for (text, key) in [
        (
            "size = [1e-6, 0]\nheight_map = [[0, 1e-9], [0]]",
            "height_map",
        ),
        ("size = [1e-6, 0]\nheight_map = [[0, 1]]", "height_map"),
        ("size = [1e-6, 0]\nheight_map = 3", "height_map"),
        (
            "size = [1e-6, 0]\n[[domain]]\nname = \"d\"\nx = [0, 1e-7]\nwidth = -1e-9",
            "domain 'd' width",
        ),
    ] {
        let e = SampleMap::parse(text, "<test>").unwrap_err().to_string();
        assert!(e.contains(key), "{e}");
    }
}

/// Height maps read from files (feature `files`): a CSV and an NPY file hold the same heights
/// as the rows given inline, and their refusals name `height_map` and the file.
#[cfg(feature = "files")]
mod height_map_files {
    use afmdyn::request::image::SampleMap;
    use std::path::{Path, PathBuf};

    /// Rows of heights (m) that are not round numbers: the files must give them bit for bit.
    fn rows() -> Vec<Vec<f64>> {
        vec![
            vec![0.0, 1.234_567_890_123_456_7e-9, -2.5e-9, 3e-10],
            vec![4.1e-9, 5.000_000_000_000_001e-9, 6.02e-9, -7.7e-9],
            vec![9.999e-6, -1e-5, 1e-12, 2.718_281_828_459_045e-9],
        ]
    }

    /// A fresh directory under the system's temporary one.
    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("afmdyn-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// `rows` as CSV: each height in Rust's shortest round-trip form.
    fn write_csv(path: &Path, rows: &[Vec<f64>]) {
        let text: String = rows
            .iter()
            .map(|r| {
                let cells: Vec<String> = r.iter().map(|h| format!("{h:e}")).collect();
                cells.join(", ") + "\n"
            })
            .collect();
        std::fs::write(path, text).unwrap();
    }

    /// `values` (row-major over `shape`, or column-major with `fortran`) as an NPY file of the
    /// default dtype of `T`.
    fn write_npy<T: npyz::AutoSerialize + Copy>(
        path: &Path,
        shape: &[u64],
        values: &[T],
        fortran: bool,
    ) {
        use npyz::WriterBuilder;
        let order = if fortran {
            npyz::Order::Fortran
        } else {
            npyz::Order::C
        };
        let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
        let mut w = npyz::WriteOptions::<T>::new()
            .default_dtype()
            .order(order)
            .shape(shape)
            .writer(file)
            .begin_nd()
            .unwrap();
        w.extend(values.iter().copied()).unwrap();
        w.finish().unwrap();
    }

    fn map_text(height_map: &str) -> String {
        format!(
            "size = [1e-6, 2e-6]\nheight_map = {height_map}\n[[domain]]\nname = \"t\"\n\
             x = [0.5e-6, 1e-6]\nheight = 2e-9\nwidth = 0.1e-6\n"
        )
    }

    /// The inline map's heights at a grid of points, nodes and between them, against `map`'s:
    /// exactly equal.
    fn same_heights(map: &SampleMap, inline: &SampleMap) {
        assert_eq!(map.height_map, inline.height_map);
        for j in 0..=12 {
            for i in 0..=15 {
                let (x, y) = (i as f64 * 1e-6 / 15.0, j as f64 * 2e-6 / 12.0);
                assert_eq!(map.height_at(x, y), inline.height_at(x, y), "({x}, {y})");
            }
        }
    }

    #[test]
    fn csv_and_npy_files_give_the_inline_heights() {
        let dir = temp_dir("hmap-ok");
        let rows = rows();
        let inline = SampleMap::parse(
            &map_text(&serde_json::to_string(&rows).unwrap()),
            "<inline>",
        )
        .unwrap();
        assert_eq!(inline.height_map, rows);
        write_csv(&dir.join("h.csv"), &rows);
        let flat: Vec<f64> = rows.concat();
        write_npy(&dir.join("h.npy"), &[3, 4], &flat, false);
        // the same array in Fortran order (np.save of a transposed view)
        let column_major: Vec<f64> = (0..4)
            .flat_map(|i| rows.iter().map(move |r| r[i]))
            .collect();
        write_npy(&dir.join("hf.npy"), &[3, 4], &column_major, true);
        // relative to the sample file's directory when loaded from a file
        for file in ["h.csv", "h.npy", "hf.npy"] {
            let sample = dir.join(format!("s-{file}.toml"));
            std::fs::write(&sample, map_text(&format!("\"{file}\""))).unwrap();
            let map = SampleMap::load(&sample).unwrap();
            same_heights(&map, &inline);
            assert_eq!(map.domains, inline.domains);
            // and from text, relative to the current directory (here an absolute path)
            let abs = dir.join(file).display().to_string();
            let map = SampleMap::parse(&map_text(&format!("{abs:?}")), "<text>").unwrap();
            same_heights(&map, &inline);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_height_map_files_are_refused_naming_the_file_and_the_problem() {
        let dir = temp_dir("hmap-bad");
        let w = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
        w("ragged.csv", "0, 1e-9, 2e-9\n0, 1e-9\n");
        w("word.csv", "0, 1e-9, 2e-9\n0, 1e-9, abc\n");
        w("high.csv", "0, 1e-9\n0, 2e-5\n");
        w("nan.csv", "0, NaN\n");
        w("empty.csv", "");
        w("h.txt", "0, 1e-9\n");
        w("junk.npy", "not an npy file at all");
        write_npy(
            &dir.join("f32.npy"),
            &[2, 2],
            &[0f32, 1e-9, 2e-9, 3e-9],
            false,
        );
        write_npy(&dir.join("i64.npy"), &[2, 2], &[0i64, 1, 2, 3], false);
        write_npy(&dir.join("1d.npy"), &[4], &[0.0, 1e-9, 2e-9, 3e-9], false);
        write_npy(
            &dir.join("3d.npy"),
            &[1, 2, 2],
            &[0.0, 1e-9, 2e-9, 3e-9],
            false,
        );
        write_npy(
            &dir.join("high.npy"),
            &[2, 2],
            &[0.0, 1e-9, 1e-4, 3e-9],
            false,
        );
        write_npy(&dir.join("inf.npy"), &[1, 2], &[0.0, f64::INFINITY], false);
        write_npy(&dir.join("wide.npy"), &[1, 4097], &vec![0.0; 4097], false);
        // a truncated file: its header promises more values than it holds
        write_npy(
            &dir.join("cut.npy"),
            &[2, 2],
            &[0.0, 1e-9, 2e-9, 3e-9],
            false,
        );
        let bytes = std::fs::read(dir.join("cut.npy")).unwrap();
        std::fs::write(dir.join("cut.npy"), &bytes[..bytes.len() - 5]).unwrap();
        // larger than the limits (sparse files: nothing is written, nothing is read)
        use afmdyn::request::height_map_file::{MAX_CSV_BYTES, MAX_NPY_BYTES};
        for (name, len) in [("big.csv", MAX_CSV_BYTES), ("big.npy", MAX_NPY_BYTES)] {
            let f = std::fs::File::create(dir.join(name)).unwrap();
            f.set_len(len + 1).unwrap();
        }
        // an NPY header that says it is a megabyte long
        let mut huge = b"\x93NUMPY\x02\x00".to_vec();
        huge.extend(1_000_000u32.to_le_bytes());
        huge.extend(b"{'descr': '<f8'");
        std::fs::write(dir.join("header.npy"), huge).unwrap();
        for (file, problem) in [
            ("big.csv", "larger than 536870912 bytes"),
            ("big.npy", "the limit of an NPY height map"),
            (
                "header.npy",
                "an NPY header of 1000000 bytes: at most 65536",
            ),
            ("ragged.csv", "row 2 has 2 values, row 1 has 3"),
            ("word.csv", "row 2, column 3: 'abc' is not a number"),
            (
                "high.csv",
                "row 2, column 2: 2e-5 m: heights must be within ±10 µm",
            ),
            ("nan.csv", "row 1, column 2: NaN is not a finite height"),
            ("empty.csv", "holds no heights"),
            ("h.txt", "must be a .csv file"),
            ("missing.csv", "No such file"),
            ("missing.npy", "No such file"),
            ("junk.npy", "not an NPY file"),
            ("f32.npy", "dtype '<f4': must be float64"),
            ("i64.npy", "dtype '<i8': must be float64"),
            ("1d.npy", "a 1-D array of shape [4]: must be 2-D"),
            ("3d.npy", "a 3-D array"),
            (
                "high.npy",
                "row 2, column 1: 1e-4 m: heights must be within ±10 µm",
            ),
            ("inf.npy", "row 1, column 2: inf is not a finite height"),
            ("wide.npy", "shape (1, 4097): at most 4096 × 4096"),
            ("cut.npy", "cannot be read (a truncated file?)"),
        ] {
            let sample = dir.join("s.toml");
            std::fs::write(&sample, map_text(&format!("\"{file}\""))).unwrap();
            let e = SampleMap::load(&sample).unwrap_err();
            let msg = e.to_string();
            assert!(
                matches!(e, afmdyn::SimError::Probe(_)),
                "{file}: not a sample map error: {e:?}"
            );
            assert!(
                msg.contains(&format!("height_map = \"{file}\""))
                    && msg.contains(&dir.join(file).display().to_string())
                    && msg.contains(&sample.display().to_string()),
                "{file}: {msg}"
            );
            assert!(msg.contains(problem), "{file}: {msg}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// Without the `files` feature (the WebAssembly build) a height map file is refused, naming
/// `height_map` and the feature.
#[cfg(not(feature = "files"))]
#[test]
fn without_files_a_height_map_file_is_refused() {
    let e = SampleMap::parse("size = [1e-6, 0]\nheight_map = \"h.csv\"", "<test>").unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, afmdyn::SimError::Probe(_)), "{e:?}");
    assert!(
        msg.contains("height_map = \"h.csv\"") && msg.contains("`files` feature"),
        "{msg}"
    );
}

/// A setpoint inside the jump of the approach sweep (issue 77: a crossing dropped without a
/// word): on `examples/probe-point-mass-dmt.toml` without branches, the approach's largest
/// step in A/A₀ between two stable period-1 points is its jump at the fold; the setpoint at
/// the jump's middle crosses it, no stable orbit runs from one side to the other, and the
/// crossing is left out — said in the setpoint's warnings, naming the two z_c of the jump.
#[test]
fn a_setpoint_in_a_jump_of_the_curve_is_said_not_left_out() {
    let p = Probe::parse(&repo("examples/probe-point-mass-dmt.toml"), "<test>").unwrap();
    let u = CurveUnits::from_scales(&p.scales, false);
    let req = CurveRequest {
        points: Some(60),
        branches: false,
        ..CurveRequest::default()
    };
    let spec = approach_request(p.params, &req, u.length, false).unwrap();
    let c = approach_retract(&spec).unwrap();
    let ratio = |i: usize| {
        let o = &c.first[i].observables;
        o.amplitude / o.closed_form.free_amplitude
    };
    let jump = (0..c.first.len() - 1)
        .filter(|&i| c.first[i].stable && c.first[i + 1].stable)
        .max_by(|&i, &j| {
            (ratio(i) - ratio(i + 1))
                .abs()
                .total_cmp(&(ratio(j) - ratio(j + 1)).abs())
        })
        .unwrap();
    let (r0, r1) = (ratio(jump), ratio(jump + 1));
    assert!((r0 - r1).abs() > 0.02, "no jump: {r0} {r1}");
    let r = 0.5 * (r0 + r1);
    let (points, dropped) = afmdyn::analysis::setpoint::operating_points(&spec, &c, r).unwrap();
    assert!(
        dropped.iter().any(|k| k.index == jump),
        "{dropped:?} {points:?}"
    );
    let doc = setpoint(&p.params, &c, (&points, &dropped), r, &u);
    let warnings = doc["warnings"].as_array().expect("warnings");
    let z = |i: usize| {
        afmdyn::error::number(
            p.params.with(spec.param, c.first[i].value).rest_distance() * u.length,
        )
    };
    assert!(
        warnings.iter().any(|w| {
            let w = w.as_str().unwrap();
            w.contains("no operating point is listed")
                && w.contains(&format!(
                    "between z_c = {} m and {} m on the approach",
                    z(jump),
                    z(jump + 1)
                ))
        }),
        "{warnings:?}"
    );
}
