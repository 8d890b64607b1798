// The off-resonance (PeakForce) tap of `afmdyn peakforce --json` drawn as the instrument shows
// it: the force–distance curve (approach and retract) and one modulation period against time,
// with the instrument's channels (issue 61; docs/tutorials/peakforce.md). Data in, figures out:
// no numerics here.

const SI = { exponentformat: "SI" };
const MARGIN = { l: 75, r: 10, t: 30, b: 50 };

const trace = (x, y, name, color, extra = {}) =>
  ({ type: "scatter", mode: "lines", x, y, name, line: { color, width: 1.5 }, ...extra });

const figure = (title, x, y) => ({
  margin: MARGIN, title: { text: title, font: { size: 13 } }, hovermode: "closest",
  xaxis: { title: { text: x }, ...SI }, yaxis: { title: { text: y }, ...SI },
  legend: { orientation: "h", y: -0.25 },
});

/** The two figures and the summary of a peakforce document `d`, in SI (a probe's document):
 * `a` the force against the tip–sample distance, approach and retract (the filtered force
 * too when the document has it); `b` the tip deflection and the force over one period. */
export function peakforceView(d, colours) {
  const c = d.curve;
  const a = [
    trace(c.approach_distance, c.approach_force, "approach", colours.forward),
    trace(c.retract_distance, c.retract_force, "retract", colours.backward),
  ];
  if (c.retract_filtered_force) {
    a.push(trace(c.retract_distance, c.retract_filtered_force, "retract, filtered", "#7f8c8d",
      { line: { color: "#7f8c8d", dash: "dot", width: 1.5 } }));
  }
  const y = d.cycle;
  const b = [
    trace(y.time, y.deflection, "deflection", colours.forward),
    trace(y.time, y.force, "tip–sample force", colours.backward, { yaxis: "y2" }),
  ];
  const bLayout = figure("One modulation period: deflection (left) and force (right)", "time (s)", "deflection (m)");
  bLayout.margin = { ...MARGIN, r: 75 };
  bLayout.yaxis2 = { title: { text: "force (N)" }, overlaying: "y", side: "right", ...SI };
  const ch = d.channels;
  const e = (x, unit) => `${x.toExponential(4)} ${unit}`;
  return {
    a: { traces: a, layout: figure("Force–distance curve of the steady tap", "tip–sample distance (m)", "force (N)") },
    b: { traces: b, layout: bLayout },
    summary: [
      ["peak force", e(ch.peak_force, "N")],
      ["adhesion", e(ch.adhesion, "N")],
      ["deformation", e(ch.deformation, "m")],
      ["dissipation", e(ch.dissipation, "J per cycle")],
      ["modulus_dmt (fitted) / true E*", `${e(ch.modulus_dmt, "Pa")} / ${e(d.modulus.true, "Pa")} (ratio ${d.modulus.ratio.toFixed(4)})`],
      ["contact time, snap-off time", `${e(ch.contact_time, "s")}, ${e(ch.snap_off_time, "s")}`],
      ["ringing amplitude", e(ch.ringing_amplitude, "m")],
      ["taps per cycle", String(ch.taps_per_cycle)],
      ["f₀/f_m", d.modulation.f0_over_fm.toFixed(1)],
      ["orbit", `period ${d.orbit.period}, ${d.orbit.stable ? "stable" : "unstable"}, ${d.orbit.transient_periods} transient periods`],
      ["z_c", e(d.z_c, "m")],
    ],
  };
}

/** The rows of a peakforce CSV export: the cycle's columns (time, deflection, distance, force),
 * as `peakforce-cycle.csv` of the command line. */
export function peakforceRows(d) {
  const y = d.cycle;
  return y.time.map((t, i) => ({ time: t, deflection: y.deflection[i], distance: y.distance[i], force: y.force[i] }));
}
