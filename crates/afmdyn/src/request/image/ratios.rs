//! The ratios of an image's setpoint study (the domain contrast of height, phase and
//! dissipation over a range of amplitude ratios): their form and limit.

use super::*;

/// The most setpoints of a setpoint study, on every front end: each is a line engaged on
/// the background that crosses every domain.
pub const MAX_STUDY_RATIOS: usize = 1000;

/// Parse a setpoint study's ratios `FROM:TO:N` (N evenly spaced ratios in (0, 1), ends
/// included).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `setpoint_study` for another form, ratios outside (0, 1)
/// or N outside 2..=1000.
pub fn study_ratios(spec: &str) -> Result<Vec<f64>, SimError> {
    let bad = || {
        SimError::out_of_range(
            "setpoint_study",
            spec.to_string(),
            "must be FROM:TO:N, ratios A_sp/A0 in (0, 1) and N in 2..=1000 (MAX_STUDY_RATIOS; \
             e.g. 0.2:0.95:16)",
        )
    };
    let parts: Vec<&str> = spec.split(':').collect();
    let [from, to, n] = parts[..] else {
        return Err(bad());
    };
    let (from, to): (f64, f64) = (
        from.trim().parse().map_err(|_| bad())?,
        to.trim().parse().map_err(|_| bad())?,
    );
    let n: usize = n.trim().parse().map_err(|_| bad())?;
    let inside = |r: f64| r > 0.0 && r < 1.0;
    if !(inside(from) && inside(to) && (2..=MAX_STUDY_RATIOS).contains(&n)) {
        return Err(bad());
    }
    // (1 − t)·from + t·to: both ends exactly
    Ok((0..n)
        .map(|k| {
            let t = k as f64 / (n - 1) as f64;
            (1.0 - t) * from + t * to
        })
        .collect())
}
