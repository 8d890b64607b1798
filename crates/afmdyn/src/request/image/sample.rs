//! The sample of an image request ([`super::SampleMap`]): its domains, lengths and height
//! map read from the request's TOML, checked and resolved to the material at each pixel.

use super::*;

/// A refusal of a sample map's key: `name = value: allowed` ([`SimError::Probe`], an input
/// error; [`SampleMap::parse`] names the file).
pub(super) fn bad(name: String, value: impl std::fmt::Display, allowed: &str) -> SimError {
    SimError::Probe(format!("{name} = {value}: {allowed}"))
}

/// A length of the map (m): finite, |v| ≤ 1 m.
pub(super) fn length(v: &toml::Value, name: &str) -> Result<f64, SimError> {
    let x = v
        .as_float()
        .or_else(|| v.as_integer().map(|i| i as f64))
        .ok_or_else(|| bad(name.into(), v, "must be a number (m)"))?;
    if !(x.is_finite() && x.abs() <= 1.0) {
        return Err(bad(
            name.into(),
            x,
            "must be a finite length in m, at most 1 m",
        ));
    }
    Ok(x)
}

/// A pair [a, b] of lengths with a < b (or a ≤ b when `allow_equal`).
pub(super) fn pair(v: &toml::Value, name: &str) -> Result<(f64, f64), SimError> {
    let a = v.as_array().filter(|a| a.len() == 2).ok_or_else(|| {
        bad(
            name.into(),
            v,
            "must be an array of two lengths [from, to] (m)",
        )
    })?;
    let (x0, x1) = (length(&a[0], name)?, length(&a[1], name)?);
    if x0 >= x1 {
        return Err(bad(
            name.into(),
            format!("[{x0:e}, {x1:e}]"),
            "must be [from, to] with from < to",
        ));
    }
    Ok((x0, x1))
}

/// A height map `[[h, …], …]` (m): at most 4096 × 4096 values, rows of one length, each a
/// finite height within ±10 µm.
pub(super) fn height_map(v: &toml::Value) -> Result<Vec<Vec<f64>>, SimError> {
    let what = "must be an array of rows [[h, …], …] of heights in m (rows from y = 0, each as \
                long, at most 4096 × 4096) or the path of a .csv or .npy file of them";
    let rows = v
        .as_array()
        .filter(|r| !r.is_empty() && r.len() <= MAX_PIXELS)
        .ok_or_else(|| bad("height_map".into(), "given", what))?;
    let mut out = Vec::with_capacity(rows.len());
    for r in rows {
        let row = r
            .as_array()
            .filter(|c| !c.is_empty() && c.len() <= MAX_PIXELS)
            .ok_or_else(|| bad("height_map".into(), "a row", what))?;
        let mut hs = Vec::with_capacity(row.len());
        for h in row {
            let h = length(h, "height_map")?;
            if h.abs() > MAX_HEIGHT {
                return Err(bad("height_map".into(), h, "heights must be within ±10 µm"));
            }
            hs.push(h);
        }
        out.push(hs);
    }
    if out.iter().any(|r| r.len() != out[0].len()) {
        return Err(bad("height_map".into(), "rows of different lengths", what));
    }
    Ok(out)
}

/// A height map file `height_map = "…"` ([`crate::io::height_map::read`]), a relative path
/// taken from `dir`.
#[cfg(feature = "files")]
pub(super) fn height_map_file(
    file: &str,
    dir: Option<&std::path::Path>,
) -> Result<Vec<Vec<f64>>, SimError> {
    crate::io::height_map::read(file, dir)
}

/// Without the `files` feature a height map file is refused.
#[cfg(not(feature = "files"))]
pub(super) fn height_map_file(
    file: &str,
    _dir: Option<&std::path::Path>,
) -> Result<Vec<Vec<f64>>, SimError> {
    Err(bad(
        "height_map".into(),
        format!("\"{file}\""),
        "a height map file needs afmdyn's `files` feature: give the rows inline [[h, …], …]",
    ))
}

/// The map's `size` [Lx, Ly] (m) in its `root` table: Lx > 0, Ly ≥ 0 (0 for a line).
fn map_size(root: &toml::Table) -> Result<(f64, f64), SimError> {
    let size = root.get("size").ok_or_else(|| {
        bad(
            "size".into(),
            "missing",
            "[Lx, Ly] in m (Ly = 0 for a line)",
        )
    })?;
    let s = size.as_array().filter(|a| a.len() == 2).ok_or_else(|| {
        bad(
            "size".into(),
            size,
            "must be [Lx, Ly] in m (Ly = 0 for a line)",
        )
    })?;
    let (lx, ly) = (length(&s[0], "size")?, length(&s[1], "size")?);
    if !(lx > 0.0 && ly >= 0.0) {
        return Err(bad(
            "size".into(),
            format!("[{lx:e}, {ly:e}]"),
            "must be [Lx, Ly] with Lx > 0 and Ly ≥ 0 (m)",
        ));
    }
    Ok((lx, ly))
}

/// The `i`-th `[[domain]]` entry `e` of a map of size (`lx`, `ly`): its name, x and y ranges
/// (overlapping the map), height (within ±10 µm), width (≥ 0) and `[domain.sample]` (without
/// z_c, which the feedback sets).
fn domain(i: usize, e: &toml::Value, (lx, ly): (f64, f64)) -> Result<Domain, SimError> {
    let t = e
        .as_table()
        .ok_or_else(|| bad(format!("domain {}", i + 1), e, "must be a table"))?;
    let name = match t.get("name") {
        Some(n) => n
            .as_str()
            .ok_or_else(|| bad(format!("domain {} name", i + 1), n, "must be a string"))?
            .to_string(),
        None => format!("domain {}", i + 1),
    };
    let key = |k: &str| format!("domain '{name}' {k}");
    for k in t.keys() {
        if !matches!(
            k.as_str(),
            "name" | "x" | "y" | "height" | "width" | "sample"
        ) {
            return Err(bad(
                key(k),
                "given",
                "unknown: expected name, x, y, height, width and [domain.sample]",
            ));
        }
    }
    let x = pair(
        t.get("x")
            .ok_or_else(|| bad(key("x"), "missing", "[x0, x1] in m"))?,
        &key("x"),
    )?;
    let y = t.get("y").map(|v| pair(v, &key("y"))).transpose()?;
    if x.1 <= 0.0 || x.0 >= lx || y.is_some_and(|y| y.1 <= 0.0 || y.0 >= ly.max(0.0)) {
        return Err(bad(
            key("x, y"),
            "outside the map",
            "must overlap the map [0, Lx] × [0, Ly]",
        ));
    }
    let optional_length = |k: &str| -> Result<f64, SimError> {
        let v = t.get(k).map(|v| length(v, &key(k))).transpose()?;
        Ok(v.unwrap_or(0.0))
    };
    let height = optional_length("height")?;
    if height.abs() > MAX_HEIGHT {
        return Err(bad(
            key("height"),
            height,
            "must be within ±10 µm (a topography the z piezo follows)",
        ));
    }
    let width = optional_length("width")?;
    if width < 0.0 {
        return Err(bad(key("width"), width, "must be ≥ 0 (m)"));
    }
    let sample = match t.get("sample") {
        None => None,
        Some(v) => {
            let s = v
                .as_table()
                .ok_or_else(|| bad(key("sample"), v, "must be a table ([domain.sample])"))?;
            if s.contains_key("z_c") {
                return Err(bad(
                    key("sample.z_c"),
                    "given",
                    "is set by the feedback, not by the sample",
                ));
            }
            Some(s.clone())
        }
    };
    Ok(Domain {
        name,
        x,
        y,
        height,
        width,
        sample,
    })
}

impl SampleMap {
    /// Parse a sample map from TOML text; `origin` names it in errors. A height map file
    /// (`height_map = "h.csv"`) is read from the current directory when its path is relative.
    ///
    /// # Errors
    /// [`SimError::Probe`] naming the file and the key (`size`, `domain 'soft' x`, …) and what
    /// it must be: an unknown key, a missing `size` or `x`, a range that is empty or outside the
    /// map, more than `MAX_DOMAINS` domains; the syntax error of invalid TOML; a height map
    /// file's refusals ([`crate::io::height_map::read`]), or, without the `files` feature, any
    /// height map file.
    pub fn parse(text: &str, origin: &str) -> Result<SampleMap, SimError> {
        Self::parse_in(text, origin, None)
    }

    /// [`SampleMap::parse`] with a relative height map file taken from `dir` (`None`: the
    /// current directory).
    pub(super) fn parse_in(
        text: &str,
        origin: &str,
        dir: Option<&std::path::Path>,
    ) -> Result<SampleMap, SimError> {
        Self::parse_text(text, dir)
            .map_err(|e| SimError::Probe(format!("sample map {origin}: {e}")))
    }

    /// [`SampleMap::parse_in`] without the file's name in its errors.
    pub(super) fn parse_text(
        text: &str,
        dir: Option<&std::path::Path>,
    ) -> Result<SampleMap, SimError> {
        let root: toml::Table = text.parse().map_err(|e: toml::de::Error| {
            SimError::Probe(format!(
                "invalid TOML: {}",
                e.to_string().replace('\n', " ")
            ))
        })?;
        for k in root.keys() {
            if !matches!(k.as_str(), "size" | "domain" | "height_map") {
                return Err(bad(
                    format!("sample map key '{k}'"),
                    "given",
                    "unknown: expected size, height_map and [[domain]] entries",
                ));
            }
        }
        let size = map_size(&root)?;
        let entries = match root.get("domain") {
            None => Vec::new(),
            Some(v) => v
                .as_array()
                .ok_or_else(|| bad("domain".into(), v, "must be [[domain]] tables"))?
                .clone(),
        };
        if entries.len() > MAX_DOMAINS {
            return Err(bad("domain".into(), entries.len(), "at most 1000 domains"));
        }
        let domains = (entries.iter().enumerate())
            .map(|(i, e)| domain(i, e, size))
            .collect::<Result<Vec<_>, _>>()?;
        let height_map = match root.get("height_map") {
            None => Vec::new(),
            Some(toml::Value::String(file)) => height_map_file(file, dir)?,
            Some(v) => height_map(v)?,
        };
        Ok(SampleMap {
            size,
            domains,
            height_map,
        })
    }

    /// A sample map from a front end's string: TOML text when it holds a line break or `=`
    /// (every map has a `size = …` line), else the path of a file ([`SampleMap::load`]).
    ///
    /// # Errors
    /// As [`SampleMap::load`] and [`SampleMap::parse`].
    #[cfg(feature = "files")]
    pub(crate) fn read(source: &str) -> Result<SampleMap, SimError> {
        if source.contains(['\n', '=']) {
            Self::parse(source, "<text>")
        } else {
            Self::load(std::path::Path::new(source))
        }
    }

    /// Read a sample map file; a relative height map file (`height_map = "h.csv"`) is taken
    /// from its directory.
    ///
    /// # Errors
    /// [`SimError::Probe`] naming the file when it cannot be read (or is larger than
    /// [`crate::request::limits::MAX_INPUT_TEXT_BYTES`]); as [`SampleMap::parse`].
    #[cfg(feature = "files")]
    pub fn load(path: &std::path::Path) -> Result<SampleMap, SimError> {
        let text = crate::io::read_text(path, crate::io::InputKind::SampleMap)
            .map_err(|e| SimError::Probe(format!("sample map: {e}")))?;
        Self::parse_in(&text, &path.display().to_string(), path.parent())
    }

    /// The map with `rows` as its height map (m, `[row][column]`, rows from y = 0), replacing any
    /// it had: a front end's array (Python's `height_map=`), checked as the TOML key is.
    ///
    /// # Errors
    /// [`SimError::Probe`] naming `height_map`: empty, rows of different lengths, more than
    /// 4096 × 4096 values, a height not finite or beyond ±10 µm.
    #[cfg(feature = "files")]
    pub(crate) fn with_height_map(mut self, rows: Vec<Vec<f64>>) -> Result<SampleMap, SimError> {
        let v = toml::Value::Array(
            rows.into_iter()
                .map(|r| toml::Value::Array(r.into_iter().map(toml::Value::Float).collect()))
                .collect(),
        );
        self.height_map = height_map(&v)?;
        Ok(self)
    }

    /// The true height at (x, y) (m): the top domain's height, risen over its `width` inside its
    /// edges (smoothstep), plus the height map's bilinear interpolation there.
    pub(crate) fn height_at(&self, x: f64, y: f64) -> f64 {
        let domain = self.domain_at(x, y).map_or(0.0, |k| {
            let d = &self.domains[k];
            if d.width <= 0.0 {
                return d.height;
            }
            // the distance to the nearest edge inside the map (the map's own edges are not
            // steps)
            let (lx, ly) = self.size;
            let mut edge = f64::INFINITY;
            for (e, lo, hi, v) in [(d.x.0, 0.0, lx, x), (d.x.1, 0.0, lx, x)] {
                if e > lo && e < hi {
                    edge = edge.min((v - e).abs());
                }
            }
            if let Some((y0, y1)) = d.y {
                for e in [y0, y1] {
                    if e > 0.0 && e < ly {
                        edge = edge.min((y - e).abs());
                    }
                }
            }
            let t = (edge / d.width).min(1.0);
            d.height * t * t * (3.0 - 2.0 * t)
        });
        domain + self.map_height(x, y)
    }

    /// The height map's bilinear interpolation at (x, y) (0 without a map).
    pub(super) fn map_height(&self, x: f64, y: f64) -> f64 {
        let rows = self.height_map.len();
        if rows == 0 {
            return 0.0;
        }
        let cols = self.height_map[0].len();
        // grid position: column i at x = i Lx/(cols − 1), row j at y = j Ly/(rows − 1)
        let pos = |v: f64, len: f64, n: usize| {
            if n < 2 || len <= 0.0 {
                (0, 0.0)
            } else {
                let p = (v / len * (n - 1) as f64).clamp(0.0, (n - 1) as f64);
                let k = (p.floor() as usize).min(n - 2);
                (k, p - k as f64)
            }
        };
        let (i, fx) = pos(x, self.size.0, cols);
        let (j, fy) = pos(y, self.size.1, rows);
        let at = |jj: usize, ii: usize| self.height_map[jj.min(rows - 1)][ii.min(cols - 1)];
        let top = at(j, i) * (1.0 - fx) + at(j, i + 1) * fx;
        let bottom = at(j + 1, i) * (1.0 - fx) + at(j + 1, i + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The domain at (x, y) (m): the last listed that contains it, `None` for the background.
    pub(crate) fn domain_at(&self, x: f64, y: f64) -> Option<usize> {
        self.domains.iter().rposition(|d| {
            (d.x.0..=d.x.1).contains(&x) && d.y.is_none_or(|(y0, y1)| (y0..=y1).contains(&y))
        })
    }
}
