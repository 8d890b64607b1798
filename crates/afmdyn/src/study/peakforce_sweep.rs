//! The running of `peakforce` with a sweep (`crate::request::peakforce_sweep`): its block of
//! the document ([`sweep_document`]), its warnings and its layout ([`sweep_layout`]).

use crate::analysis::peakforce::SteadyTap;
use crate::layout::columns::{self, UnitNames};
use crate::layout::{Layout, Values, Variable};
pub(crate) use crate::report::present::peakforce::{Frame, SweepTap, COLUMNS, NOISE_COLUMNS};
use crate::request::PeakForceSweep;
use serde_json::{json, Value};

/// The `sweep` block of the document: the swept quantity and its values, each channel of
/// [`COLUMNS`] (`z_c` the feedback's with a setpoint; `modulus_dmt` the frame's modulus scale ×
/// the fitted Hertz group; with a temperature, [`NOISE_COLUMNS`] after them) over them (`null` where a point failed) and their units, the orbit's
/// period and stability, and each point's message (`null` when computed).
pub(crate) fn sweep_document(sweep: &PeakForceSweep, frame: &Frame, taps: &[SweepTap]) -> Value {
    let si = frame.u.si;
    let names = UnitNames::si_or_model(si);
    let (mut channels, mut units) = (
        columns::arrays(&COLUMNS, frame, taps),
        columns::units(&COLUMNS, &names),
    );
    if with_noise(taps) {
        channels.extend(columns::arrays(&NOISE_COLUMNS, frame, taps));
        units.extend(columns::units(&NOISE_COLUMNS, &names));
    }
    json!({
        "quantity": sweep.quantity.name(),
        "unit": sweep.quantity.unit(si),
        "values": sweep.values,
        "channels": channels,
        "units": units,
        "period": taps.iter().map(|t| t.tap.as_ref().map(|t| t.period)).collect::<Vec<_>>(),
        "stable": taps.iter().map(|t| t.tap.as_ref().map(|t| t.stable)).collect::<Vec<_>>(),
        "transient_periods": taps.iter().map(|t| t.tap.as_ref().map(|t| t.transient_periods)).collect::<Vec<_>>(),
        "evaluations": taps.iter().map(|t| t.evaluations).collect::<Vec<_>>(),
        "message": taps.iter().map(|t| t.message.clone()).collect::<Vec<_>>(),
        "warnings": taps
            .iter()
            .map(|t| {
                t.tap.as_ref().map_or(Vec::new(), |tap| {
                    tap_warnings(tap)
                        .into_iter()
                        .map(|(_, w)| w)
                        .collect()
                })
            })
            .collect::<Vec<Vec<String>>>(),
    })
}

/// Whether the sweep carries the thermal noise's columns ([`NOISE_COLUMNS`]: run with a
/// temperature, some tap has its noise).
fn with_noise(taps: &[SweepTap]) -> bool {
    taps.iter().any(|t| t.noise.is_some())
}

/// What may make a steady tap's channels misleading, each with its kind (`period`, `double-tap`,
/// `unstable`, `no-contact`) and its message: a period-n orbit (the cycle shows the first
/// period), more than one contact per modulation period (`modulus_dmt` is then not meaningful),
/// an unstable orbit, no repulsive contact. Every tap of a sweep is checked alike
/// ([`sweep_warnings`]), and a single tap's document has them ([`super::peakforce::document`]).
pub(crate) fn tap_warnings(tap: &SteadyTap) -> Vec<(&'static str, String)> {
    let c = &tap.channels;
    let mut warnings = Vec::new();
    if tap.period > 1 {
        warnings.push((
            "period",
            warning!(
                "peakforce.period",
                "Nothing: the cycle shows the first of its modulation periods.",
                "period-{} tapping: the orbit repeats after {} modulation periods; the cycle \
                 shows the first",
                tap.period,
                tap.period
            ),
        ));
    }
    if c.taps_per_cycle > 1.0 + 1e-9 {
        warnings.push((
            "double-tap",
            warning!(
                "peakforce.double-tap",
                "Read modulus_dmt of this cycle as not meaningful.",
                "{} contacts per modulation period: double taps (the lever's ringing reaches the \
                 sample again); modulus_dmt, fitted as PF-QNM does on the retract of one tap, is \
                 not meaningful for such a cycle",
                c.taps_per_cycle
            ),
        ));
    }
    if !tap.stable {
        warnings.push((
            "unstable",
            warning!(
                "peakforce.unstable",
                "Read the values as those of an orbit the lever does not stay on; \
                 simulate the cycle to see its motion.",
                "the steady tap is unstable (a Floquet multiplier outside the unit circle)"
            ),
        ));
    }
    if c.peak_force <= 0.0 {
        // the sample may indent the tip and still pull: adhesion outweighs the elastic
        // repulsion at the deepest indentation (issue 77: this was said as "never reaches")
        let why = if c.deformation > 0.0 {
            "the tip indents the sample but adhesion outweighs the elastic repulsion at the \
             deepest indentation (the peak force is an attraction)"
        } else {
            "the sample never reaches the tip at this z_c"
        };
        warnings.push((
            "no-contact",
            warning!(
                "peakforce.no-contact",
                "Lower z_c until the tip presses on the sample.",
                "no repulsive contact: {why}"
            ),
        ));
    }
    warnings
}

/// The sweep's warnings for the document: each kind of [`tap_warnings`]
/// once, with the number of values it holds at and the swept values where it does (the
/// first three and the last, in `block`'s units), its message the first such tap's; the
/// per-value messages are in `sweep.warnings`.
pub(crate) fn sweep_warnings(block: &Value, taps: &[SweepTap]) -> Vec<String> {
    let quantity = block["quantity"].as_str().unwrap_or("value");
    let unit = block["unit"].as_str().unwrap_or("");
    let values: Vec<f64> = block["values"].as_array().map_or(Vec::new(), |a| {
        a.iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect()
    });
    // (kind, first message, indices), in the order the kinds first appear
    let mut kinds: Vec<(&'static str, String, Vec<usize>)> = Vec::new();
    for (i, t) in taps.iter().enumerate() {
        let Some(tap) = &t.tap else { continue };
        for (kind, message) in tap_warnings(tap) {
            match kinds.iter_mut().find(|k| k.0 == kind) {
                Some(k) => k.2.push(i),
                None => kinds.push((kind, message, vec![i])),
            }
        }
    }
    kinds
        .into_iter()
        .map(|(_, message, at)| {
            let show = |&i: &usize| {
                values
                    .get(i)
                    .map_or_else(|| format!("#{i}"), |&v| crate::error::number(v))
            };
            let mut list: Vec<String> = at.iter().take(3).map(show).collect();
            if at.len() > 4 {
                list.push("…".into());
            }
            if at.len() > 3 {
                list.push(show(at.last().expect("non-empty")));
            }
            warning!(
                "peakforce.sweep",
                "Read sweep.warnings for each value's own warning.",
                "at {} of the sweep's {} values ({quantity} = {} {unit}): {message} (each \
                 value's in sweep.warnings)",
                at.len(),
                taps.len(),
                list.join(", ")
            )
        })
        .collect()
}

/// The sweep's layout: the values as the coordinate of the dimension named after the swept
/// quantity, every channel of [`COLUMNS`] over it but the swept one (NaN where a point failed;
/// `modulus_dmt` last), and `period` (0 where a point failed).
pub(crate) fn sweep_layout(sweep: &PeakForceSweep, frame: &Frame, taps: &[SweepTap]) -> Layout {
    let (dim, si) = (sweep.quantity.name(), frame.u.si);
    let d = [dim];
    let unit = sweep.quantity.unit(si);
    let swept = format!("swept {dim}");
    let mut variables = vec![Variable::f64(dim, &d, unit, swept, &sweep.values)];
    let names = UnitNames::si_or_model(si);
    let mut channels = columns::variables(&COLUMNS, frame, taps, &d, &names);
    // the swept z_c is the coordinate itself
    channels.retain(|v| v.name != dim);
    // the layout lists the modulus last (the table after ringing_amplitude)
    let modulus = channels.iter().position(|v| v.name == "modulus_dmt");
    let modulus = channels.remove(modulus.expect("a column"));
    variables.extend(channels.into_iter().chain([modulus]));
    if with_noise(taps) {
        variables.extend(columns::variables(&NOISE_COLUMNS, frame, taps, &d, &names));
    }
    let period = taps
        .iter()
        .map(|t| t.tap.as_ref().map_or(0.0, |t| t.period as f64));
    variables.push(Variable::new(
        "period",
        &d,
        "modulation periods",
        "period of the orbit (0: the point failed)",
        Values::F64(period.collect()),
    ));
    Layout::new("peakforce sweep", &[(dim, sweep.values.len())], variables)
}
