// The AFM workspace's figures: the curves (approach–retract, resonance, FM with its force
// reconstruction, bimodal), the images and the PeakForce tap, drawn from the documents the
// engine returns (`afmdyn … --json`'s). Data in, figures out: no numerics here.
import Plotly from "plotly.js-cartesian-dist-min";
import { $, COLOURS, PLOT_CONFIG, summary } from "./dom.js";
import { peakforceView } from "./peakforce.js";

function lines(x, y, name, color, extra = {}) {
  return { type: "scatter", mode: "lines+markers", x, y, name, line: { color }, marker: { size: 4 }, ...extra };
}

/** Continued branches: stable parts solid, unstable dashed, one trace per run. */
function branchTraces(branches, xKey, yKey) {
  const out = [];
  branches.forEach((b, bi) => {
    let run = null;
    b[xKey].forEach((x, i) => {
      const st = b.stable[i];
      if (!run || run.stable !== st) {
        if (run) { run.x.push(x); run.y.push(b[yKey][i]); }
        run = { stable: st, x: [], y: [] };
        out.push(run);
      }
      run.x.push(x);
      run.y.push(b[yKey][i]);
    });
    void bi;
  });
  return out.map((r, i) => ({
    type: "scatter", mode: "lines", x: r.x, y: r.y, showlegend: i < 2,
    name: r.stable ? "continued branch, stable" : "continued branch, unstable",
    legendgroup: r.stable ? "stable" : "unstable",
    line: { color: "#2c3e50", width: 1.5, dash: r.stable ? "solid" : "dash" },
  }));
}

const AXIS_UNITS = { modulus_dmt: "Pa", adhesion: "N", deformation: "m", dissipation: "J", amplitude: "m", z_c: "m", peak_force: "N", indentation: "m", energy_dissipated: "J", virial: "J", phase_deg: "°", frequency_hz: "Hz", frequency_shift: "Hz" };
const AXIS_NAMES = { modulus_dmt: "modulus (DMT fit, PF-QNM)", adhesion: "adhesion", deformation: "deformation", dissipation: "dissipation per cycle", amplitude: "amplitude A", z_c: "z_c (rest tip–sample distance)", peak_force: "peak force", indentation: "indentation", energy_dissipated: "E_dis (dissipated energy per period)", virial: "virial", phase_deg: "phase", frequency_hz: "drive frequency", frequency_shift: "frequency shift Δf" };
const axis = (k) => ({ title: { text: `${AXIS_NAMES[k] ?? k} (${AXIS_UNITS[k] ?? ""})` }, exponentformat: "SI" });

/** The share of its magnitude below which a plotted quantity's spread is round-off, not
 * structure (a quantity held by a loop, as FM-AFM's phase at 90° to its tolerance): such an axis
 * is drawn over ±FLAT_SHOWN of its magnitude, so that the noise is not magnified into a
 * scribble and its ticks into overlapping 12-digit labels. Rendering only: the values (hover,
 * export) are the engine's. */
const FLAT_SPREAD = 1e-6;
const FLAT_SHOWN = 1e-3;

/** Plotly.react of an AFM plot, each y axis whose data spread is round-off (FLAT_SPREAD) given a
 * fixed range about its middle and said to be constant in the plot's title. */
function react(div, traces, layout) {
  const flat = [];
  for (const [name, ref] of [["yaxis", "y"], ["yaxis2", "y2"]]) {
    const ys = traces.filter((t) => (t.yaxis ?? "y") === ref).flatMap((t) => t.y ?? [])
      .filter((v) => typeof v === "number" && Number.isFinite(v));
    if (!ys.length) continue;
    const lo = Math.min(...ys);
    const hi = Math.max(...ys);
    const mag = Math.max(Math.abs(lo), Math.abs(hi));
    if (mag > 0 && hi - lo <= FLAT_SPREAD * mag) {
      const mid = (lo + hi) / 2;
      layout[name] = { ...layout[name], range: [mid - FLAT_SHOWN * mag, mid + FLAT_SHOWN * mag], autorange: false };
      flat.push(name);
    }
  }
  if (flat.length) {
    const text = `${layout.title?.text ?? ""} — constant to ${FLAT_SPREAD.toExponential(0)} of its size`;
    layout.title = { ...layout.title, text };
  }
  Plotly.react(div, traces, layout, PLOT_CONFIG);
}

/** Draw an AFM workspace's result `afm` (`{analysis, doc, reconstruction}`) into its plots,
 * summary and warnings; `y` the quantity of the second plot (the afm-y menu's value). */
export function drawAfmDocument(afm, y) {
  const d = afm.doc;
  const kind = afm.analysis;
  // the reconstruction's plot, shown before it is drawn (a plot drawn hidden has no size)
  $("afm-plot-c").hidden = !(kind === "fm" && afm.reconstruction?.force);
  const layout = (title, xk, yk) => ({
    margin: { l: 75, r: 10, t: 30, b: 50 }, title: { text: title, font: { size: 13 } },
    xaxis: axis(xk), yaxis: axis(yk), legend: { orientation: "h", y: -0.25 }, hovermode: "closest",
  });
  if (kind === "approach") {
    const plot = (div, yk, title) => {
      const traces = [
        lines(d.approach.z_c, d.approach[yk], "approach", COLOURS.forward),
        lines(d.retract.z_c, d.retract[yk], "retract", COLOURS.backward),
        ...branchTraces(d.branches, "z_c", yk),
      ];
      const shapes = d.folds.map((z) => ({ type: "line", xref: "x", yref: "paper", x0: z, x1: z, y0: 0, y1: 1, line: { color: "#8e44ad", dash: "dot", width: 1 } }));
      if (d.setpoint) {
        const pts = d.setpoint.points;
        traces.push({ type: "scatter", mode: "markers", x: pts.map((p) => p.z_c), y: pts.map((p) => p[yk]), name: `setpoint A/A₀ = ${d.setpoint.ratio}`, marker: { size: 11, symbol: "star", color: COLOURS.selected } });
        if (yk === "amplitude") shapes.push({ type: "line", xref: "paper", yref: "y", x0: 0, x1: 1, y0: d.setpoint.amplitude, y1: d.setpoint.amplitude, line: { color: COLOURS.selected, dash: "dash", width: 1 } });
      }
      react(div, traces, { ...layout(title, "z_c", yk), shapes });
    };
    plot("afm-plot-a", "amplitude", "Approach–retract: amplitude (folds dotted)");
    plot("afm-plot-b", y, `Approach–retract: ${AXIS_NAMES[y]}`);
    const sp = d.setpoint?.points ?? [];
    summary($("afm-summary"), [
      ["free amplitude A₀", `${d.free_amplitude.toExponential(4)} m`],
      ["folds (z_c)", d.folds.length ? d.folds.map((z) => `${z.toExponential(4)} m`).join(", ") : "none"],
      ["bistable ranges", d.bistable.length ? d.bistable.map(([a, b]) => `${a.toExponential(3)}–${b.toExponential(3)} m`).join(", ") : "none"],
      ...sp.map((p) => [`setpoint ${d.setpoint.ratio} (${p.source})`,
        `z_c = ${p.z_c.toExponential(4)} m, ${p.regime}, phase ${p.phase_deg.toFixed(2)}°, E_dis = ${p.energy_dissipated.toExponential(3)} J, peak force ${p.peak_force.toExponential(3)} N`]),
      ["Tabor parameter", d.si?.tabor_parameter?.toFixed(3) ?? "—"],
    ]);
  } else if (kind === "resonance") {
    const plot = (div, yk, title) => react(div, [
      lines(d.up.frequency_hz, d.up[yk], "sweep up", COLOURS.forward),
      lines(d.down.frequency_hz, d.down[yk], "sweep down", COLOURS.backward),
      ...branchTraces(d.branches, "frequency_hz", yk),
    ], layout(title, "frequency_hz", yk));
    plot("afm-plot-a", "amplitude", "Resonance curve: amplitude");
    plot("afm-plot-b", "phase_deg", "Resonance curve: phase");
    summary($("afm-summary"), [
      ["folds (Hz)", d.folds.length ? d.folds.map((f) => f.toFixed(1)).join(", ") : "none"],
      ["free amplitude A₀", `${d.free_amplitude.toExponential(4)} m`],
    ]);
  } else if (kind === "bimodal") {
    const modeTraces = (key, label) => [1, 2].flatMap((m) => [
      lines(d.approach.z_c, d.approach[`${key}_${m}${key === "phase" ? "_deg" : ""}`], `mode ${m}, approach`, m === 1 ? COLOURS.forward : "#16a085"),
      lines(d.retract.z_c, d.retract[`${key}_${m}${key === "phase" ? "_deg" : ""}`], `mode ${m}, retract`, m === 1 ? COLOURS.backward : "#d35400", { line: { dash: "dot", color: m === 1 ? COLOURS.backward : "#d35400" } }),
    ]).map((t) => ({ ...t, name: `${label} ${t.name}` }));
    // A₂ is often a small fraction of A₁: on its own axis (right), so that it is not drawn
    // flat along A₁'s
    const amp = modeTraces("amplitude", "A").map((t, i) => (i >= 2 ? { ...t, yaxis: "y2" } : t));
    const ampLayout = layout("Bimodal: each mode's amplitude (A₂ on the right axis)", "z_c", "amplitude");
    ampLayout.margin = { ...ampLayout.margin, r: 75 };
    ampLayout.yaxis = { ...ampLayout.yaxis, title: { text: "mode 1 amplitude A₁ (m)" } };
    ampLayout.yaxis2 = { title: { text: "mode 2 amplitude A₂ (m)" }, exponentformat: "SI", overlaying: "y", side: "right" };
    react("afm-plot-a", amp, ampLayout);
    react("afm-plot-b", modeTraces("phase", "φ"), layout("Bimodal: each mode's phase", "z_c", "phase_deg"));
    summary($("afm-summary"), [
      ["drive components", JSON.stringify(d.drive_components.frequency ?? d.drive_components)],
      ["folds (z_c)", d.folds.length ? d.folds.map((z) => `${z.toExponential(4)} m`).join(", ") : "none"],
    ]);
  } else if (kind === "image") {
    drawImage(d, y);
  } else if (kind === "peakforce") {
    const v = peakforceView(d, COLOURS);
    react("afm-plot-a", v.a.traces, v.a.layout);
    react("afm-plot-b", v.b.traces, v.b.layout);
    summary($("afm-summary"), v.summary);
  } else {
    const c = d.curve;
    const yk = c[y] ? y : "amplitude";
    react("afm-plot-a", [lines(c.z_c, c.frequency_shift, "Δf", COLOURS.forward)],
      layout("FM-AFM: frequency shift", "z_c", "frequency_shift"));
    react("afm-plot-b", [lines(c.z_c, c[yk], AXIS_NAMES[yk], COLOURS.backward)],
      layout(`FM-AFM: ${AXIS_NAMES[yk]}${yk === "phase_deg" ? " (held by the PLL)" : ""}`, "z_c", yk));
    summary($("afm-summary"), [
      ["method", d.method],
      ["amplitude", `${d.amplitude.toExponential(4)} m`],
      ["resonance frequency", `${d.resonance_frequency.toFixed(1)} Hz`],
    ]);
    const r = afm.reconstruction;
    if (r?.force) {
      react("afm-plot-c", [
        lines(r.force.distance, r.force.force, "reconstructed (Sader–Jarvis)", COLOURS.forward),
        ...(r.force.law ? [lines(r.force.distance, r.force.law, "the model's force law", "#7f8c8d", { line: { dash: "dot", color: "#7f8c8d" } })] : []),
      ], { ...layout("The force behind Δf(d): reconstruction", "distance", "force"),
        xaxis: { title: { text: "distance of closest approach d (m)" }, exponentformat: "SI" },
        yaxis: { title: { text: "tip–sample force (N)" }, exponentformat: "SI" } });
    }
  }
  const w = $("afm-warnings");
  w.replaceChildren();
  // the reconstruction's warnings, or its refusal, with the curve's
  const rec = kind === "fm" ? afm.reconstruction : null;
  const reconstructed = (rec?.error ? [rec.error] : rec?.warnings ?? []).map((m) => `reconstruction: ${m}`);
  for (const msg of [...(d.warnings ?? []), ...reconstructed]) {
    const li = document.createElement("li");
    li.textContent = typeof msg === "string" ? msg : JSON.stringify(msg);
    w.append(li);
  }
}

/** An image: maps over (y, x) as heatmaps, or a line's profiles when the map is one line. */
function drawImage(d, channel) {
  const im = d.image;
  // a PeakForce image (ideal peak-force feedback): its maps of modulus, adhesion, deformation
  // and dissipation; the setpoint a peak force (N)
  const pf = d.mode === "peakforce";
  const key = im[channel] ? channel : pf ? "modulus_dmt" : "phase_deg";
  const at = pf ? `peak force ${d.setpoint.toExponential(3)} N` : `A/A₀ = ${d.setpoint}`;
  const margin = { l: 75, r: 10, t: 30, b: 50 };
  const xTitle = { title: { text: "x (m)" }, exponentformat: "SI" };
  if (im.y.length === 1) {
    react("afm-plot-a", [
      lines(im.x, im.height[0], "apparent height", COLOURS.forward),
      lines(im.x, im.true_height[0], "true height", "#7f8c8d", { line: { dash: "dot", color: "#7f8c8d" } }),
    ], { margin, title: { text: `Line profile at ${at}`, font: { size: 13 } }, xaxis: xTitle,
      yaxis: { title: { text: "height (m)" }, exponentformat: "SI" }, legend: { orientation: "h", y: -0.25 } });
    react("afm-plot-b", [lines(im.x, im[key][0], AXIS_NAMES[key], COLOURS.backward)],
      { margin, title: { text: AXIS_NAMES[key], font: { size: 13 } }, xaxis: xTitle,
        yaxis: axis(key), legend: { orientation: "h", y: -0.25 } });
  } else {
    const heat = (div, z, name, unit) => Plotly.react(div, [{
      type: "heatmap", x: im.x, y: im.y, z, colorscale: "Viridis",
      colorbar: { title: { text: `${name} (${unit})` }, exponentformat: "SI" },
    }], { margin: { ...margin, r: 20 }, title: { text: `${name} at ${at}`, font: { size: 13 } },
      xaxis: xTitle, yaxis: { title: { text: "y (m)" }, exponentformat: "SI", scaleanchor: "x" } }, PLOT_CONFIG);
    heat("afm-plot-a", im.height, "apparent height", "m");
    heat("afm-plot-b", im[key], AXIS_NAMES[key], AXIS_UNITS[key]);
  }
  const g = (v, unit) => (typeof v === "number" ? `${v.toExponential(4)} ${unit}` : "—");
  summary($("afm-summary"), [
    ["feedback", pf ? "ideal peak-force feedback" : d.feedback],
    ["setpoint", at],
    ["pixels", `${im.x.length} × ${im.y.length}`],
    ["reference z_c", g(d.reference_z_c, "m")],
    // each material's engaged operating point beside its true modulus, and the steady taps
    ...(pf ? [...d.materials.map((m) => [m.name, m.engaged
      ? `modulus_dmt ${g(m.engaged.modulus_dmt, "Pa")} (true E* ${g(m.true_modulus, "Pa")}), adhesion ${g(m.engaged.adhesion, "N")}, deformation ${g(m.engaged.deformation, "m")}, dissipation ${g(m.engaged.dissipation, "J")}`
      : `not imaged (${m.message})`]), ["steady taps", String(d.taps)]] : []),
  ]);
}
