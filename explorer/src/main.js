// afmdyn explorer: the page. It maps form fields to the engine's requests (the JSON the
// WebAssembly build of the library reads: crates/afmdyn-wasm, docs/browser.md) and draws the
// documents it returns. No numerics live here: every number shown is the library's, the same as
// `afmdyn … --json`.
import Plotly from "plotly.js-cartesian-dist-min";
import { parse as parseToml, stringify as stringifyToml } from "smol-toml";
import { Engine, Cancelled } from "./engine.js";
import { fieldErrors, probeErrors } from "./errors.js";
import { DYN_PRESETS, DYN_FIELDS, dynModel, dynRequest } from "./dynamics.js";
import { exportData } from "./export.js";

import { $, COLOURS, PLOT_CONFIG, summary } from "./dom.js";
import { drawAfmDocument } from "./afm-plots.js";

// what the test harness and a curious user can read: the last documents and their timings
const state = {
  rows: [],
  diagram: null,
  orbit: null,
  series: null,
  afm: null,
  selected: -1,
  timings: {},
  presets: [],
  cantilevers: [],
  busy: { diagram: false, orbit: false, afm: false },
};
window.explorer = state;

let engine;
// each workspace's newest request: a cancelled one leaves the shared state alone
const generation = { diagram: 0, orbit: 0, afm: 0 };

// ---------------------------------------------------------------------------- the URL

function readHash() {
  return new URLSearchParams(location.hash.slice(1));
}

/** The AFM workspace's fields the URL keeps (by element id). */
const AFM_KEPT = ["afm-analysis", "points", "setpoint", "afm-y", "pixels", "lines", "feedback", "image-mode", "curve-from", "curve-to", "fm-amplitude"];

function writeHash() {
  const p = new URLSearchParams();
  const ws = $("tab-afm").getAttribute("aria-selected") === "true" ? "afm" : "dyn";
  p.set("ws", ws);
  for (const f of DYN_FIELDS) p.set(f, $(f).value);
  p.set("y", $("bif-y").value);
  p.set("omega", $("orbit-omega").value);
  if ($("orbit-period").value) p.set("period", $("orbit-period").value);
  p.set("probe", $("probe-preset").value);
  if ($("cantilever").value) p.set("cantilever", $("cantilever").value);
  const preset = state.presets.find((x) => x.file === $("probe-preset").value);
  if (!preset || preset.text !== $("probe-text").value) p.set("probetext", $("probe-text").value);
  for (const k of AFM_KEPT) if ($(k).value) p.set(k, $(k).value);
  p.set("sample", $("sample-preset").value);
  const sample = state.presets.find((x) => x.file === $("sample-preset").value);
  if (!sample || sample.text !== $("sample-text").value) p.set("sampletext", $("sample-text").value);
  history.replaceState(null, "", `#${p.toString()}`);
}

// ---------------------------------------------------------------------------- messages

function clearErrors(form) {
  for (const e of form.querySelectorAll(".error")) e.textContent = "";
  for (const i of form.querySelectorAll("[aria-invalid]")) i.removeAttribute("aria-invalid");
}

function showError(el, message) {
  el.textContent = message;
  const input = el.parentElement?.querySelector("input, select");
  if (input) input.setAttribute("aria-invalid", "true");
}

/** The engine's one-line message beside the field it names (else beside the button). */
function reportError(err, placeFor, fallback) {
  if (err instanceof Cancelled) return;
  const placed = placeFor(err.message);
  if (!placed.length) showError(fallback, err.message);
  else for (const [el, msg] of placed) showError(el, msg);
}

function status(el, text) {
  el.textContent = text;
}

// ---------------------------------------------------------------------------- Dynamics

/** The number in field `id` (undefined when blank); `name` is the request's key, which a
 * message names. */
function numberField(id, name = id) {
  const v = $(id).value.trim();
  if (v === "") return undefined;
  const x = Number(v);
  if (!Number.isFinite(x)) throw new FieldError(name, `${name} = ${v}: must be a number`);
  return x;
}

class FieldError extends Error {
  constructor(field, message) {
    super(message);
    this.field = field;
  }
}

function dynValues() {
  const v = {};
  for (const f of DYN_FIELDS) v[f] = f === "contact_law" ? $(f).value : numberField(f);
  return v;
}

function dynErrorPlaces(context) {
  return (message) => fieldErrors(message, (name) => {
    if (name === "omega") return context === "diagram" ? $("err-from") : $("err-omega");
    if (name === "period" || name === "initial") return $("err-period");
    return $(`err-${name}`);
  });
}

/** The selection's marker: an element over the plot at the point's pixel (the plot's own axes),
 * so that selecting redraws nothing of the diagram's thousands of points. */
function drawSelection() {
  const gd = $("bif-plot");
  const mark = $("bif-selected");
  const sel = state.rows[state.selected];
  const L = gd._fullLayout;
  const y = sel?.[$("bif-y").value];
  if (!sel || !L?.xaxis || y === null || y === undefined) {
    mark.hidden = true;
    return;
  }
  const px = L.xaxis.l2p(sel.value);
  const py = L.yaxis.l2p(y);
  mark.hidden = px < 0 || px > L._size.w || py < 0 || py > L._size.h;
  mark.style.left = `${L._size.l + px}px`;
  mark.style.top = `${L._size.t + py}px`;
}

function drawDiagram() {
  const y = $("bif-y").value;
  const traces = ["backward", "forward"].map((branch) => {
    const idx = [];
    state.rows.forEach((r, i) => { if (r.branch === branch && r[y] !== null) idx.push(i); });
    return {
      name: `${branch} continuation`,
      type: "scatter",
      mode: "markers",
      x: idx.map((i) => state.rows[i].value),
      y: idx.map((i) => state.rows[i][y]),
      customdata: idx,
      marker: { size: branch === "forward" ? 2.5 : 4, color: COLOURS[branch] },
      hovertemplate: "Ω = %{x:.4f}<br>%{y:.5g}<extra>%{fullData.name}</extra>",
    };
  });
  const label = { x_max: "X_max, tip amplitude", v_t: "V_T at the section", w_tip: "W(1, τ) at the section" }[y];
  const param = state.diagram?.param ?? "omega";
  Plotly.react("bif-plot", traces, {
    margin: { l: 70, r: 10, t: 30, b: 50 },
    title: { text: `Bifurcation diagram (${state.rows.length} points)`, font: { size: 14 } },
    xaxis: { title: { text: param === "omega" ? "Ω (dimensionless drive frequency)" : param } },
    yaxis: { title: { text: `${label} (dimensionless)` } },
    legend: { orientation: "h", y: -0.2 },
    hovermode: "closest",
    uirevision: "diagram",
  }, PLOT_CONFIG);
  drawSelection();
}

let drawPending = false;
function scheduleDraw() {
  if (drawPending) return;
  drawPending = true;
  requestAnimationFrame(() => { drawPending = false; drawDiagram(); });
}

async function runDiagram() {
  const form = $("dyn-form");
  clearErrors(form);
  let input;
  let v;
  try {
    v = dynValues();
    input = { model: dynModel(v), request: dynRequest(v) };
  } catch (e) {
    reportError(e, dynErrorPlaces("diagram"), $("err-dyn"));
    return;
  }
  writeHash();
  // a newer diagram cancels this one: only the newest resets the state it shares
  const gen = ++generation.diagram;
  state.rows = [];
  state.selected = -1;
  state.diagram = { param: "omega", input, values: v };
  state.busy.diagram = true;
  const t0 = performance.now();
  status($("dyn-status"), "computing the diagram…");
  drawDiagram();
  try {
    const { ms } = await engine.bifurcation(input, 20, (rows, total) => {
      state.rows.push(...rows);
      const done = new Set(state.rows.map((r) => `${r.index}/${r.branch}`)).size;
      status($("dyn-status"), `computing the diagram… ${done} of ${total} points`);
      scheduleDraw();
    });
    const wall = performance.now() - t0;
    state.timings.diagram_ms = wall;
    state.timings.diagram_engine_ms = ms;
    drawDiagram();
    // a point that failed is a row of status "error" with its message (the library's
    // PointStatus): said here, as the command line says it
    const failed = state.rows.filter((r) => r.status === "error");
    status($("dyn-status"),
      `diagram: ${state.rows.length} Poincaré points in ${(wall / 1000).toFixed(2)} s` +
      (failed.length ? ` — ${failed.length} point(s) failed, e.g. Ω = ${failed[0].value}: ${failed[0].message}` : ""));
  } catch (e) {
    reportError(e, dynErrorPlaces("diagram"), $("err-dyn"));
    if (!(e instanceof Cancelled)) status($("dyn-status"), "");
  } finally {
    if (gen === generation.diagram) state.busy.diagram = false;
  }
}

function fmtComplex([re, im]) {
  const m = Math.hypot(re, im);
  return `${re.toFixed(5)}${im < 0 ? " − " : " + "}${Math.abs(im).toFixed(5)}i (|μ| = ${m.toFixed(5)})`;
}

/** The series variable among `names` that the engine's layout has. */
function variable(series, names) {
  for (const n of names) if (series && series[n]) return series[n];
  return null;
}

function drawOrbit() {
  const o = state.orbit;
  summary($("orbit-summary"), [
    ["period", `${o.period} drive period${o.period > 1 ? "s" : ""}`],
    ["stable", o.stable ? "yes (every Floquet multiplier inside the unit circle)" : "no"],
    ["largest multiplier", `${fmtComplex(o.multipliers[0])}: ${o.critical}`],
    ["Floquet multipliers", o.multipliers.map(fmtComplex).join("; ")],
    ["switchings per orbit", String(o.switchings)],
    ["grazing", o.grazing ? `yes (distance ${o.grazing_distance.toExponential(2)})` : `no (distance ${o.grazing_distance.toExponential(2)})`],
    ["Poincaré points V_T", o.poincare.v_t.map((x) => x.toPrecision(10)).join(", ")],
  ]);
}

function drawSeries() {
  const s = state.series?.series;
  const t = variable(s, ["tau", "t", "time"]);
  const w = variable(s, ["w_tip", "w"]);
  const vt = variable(s, ["v_t"]);
  const wDot = variable(s, ["w_tip_dot"]);
  if (!t || !w) return;
  const unit = (v) => (v.units ? ` (${v.units})` : "");
  Plotly.react("orbit-series", [{
    type: "scatter", mode: "lines", x: t.values, y: w.values, name: "W(1, τ)",
    line: { color: COLOURS.forward },
  }, vt ? {
    type: "scatter", mode: "lines", x: t.values, y: vt.values, name: "V_T",
    line: { color: "#7f8c8d", dash: "dot" },
  } : null].filter(Boolean), {
    margin: { l: 60, r: 10, t: 30, b: 45 },
    title: { text: "Time series over the orbit", font: { size: 13 } },
    xaxis: { title: { text: t.units === "s" ? "t (s)" : t.units?.startsWith("τ") ? t.units : `τ${unit(t)}` } },
    yaxis: { title: { text: `tip displacement${unit(w)}` } },
    legend: { orientation: "h", y: -0.3 },
  }, PLOT_CONFIG);
  if (!wDot) return;
  // the phase plane of the paper's Figs. 6-17: W(1, τ) against ∂W/∂τ, the Poincaré points
  // (the samples at the drive-period sections) marked
  const spp = state.series.samples_per_period;
  const sec = w.values.map((_, i) => i).filter((i) => i % spp === 0);
  Plotly.react("orbit-phase", [{
    type: "scatter", mode: "lines", x: w.values, y: wDot.values, name: "orbit",
    line: { color: COLOURS.forward },
  }, {
    type: "scatter", mode: "markers", x: sec.map((i) => w.values[i]), y: sec.map((i) => wDot.values[i]),
    name: "Poincaré points", marker: { size: 9, color: COLOURS.selected, symbol: "x" },
  }], {
    margin: { l: 60, r: 10, t: 30, b: 45 },
    title: { text: "Phase portrait", font: { size: 13 } },
    xaxis: { title: { text: `W(1, τ)${unit(w)}` } },
    yaxis: { title: { text: `∂W(1, τ)/∂τ${unit(wDot)}` } },
    legend: { orientation: "h", y: -0.3 },
  }, PLOT_CONFIG);
}

/** The orbit through a diagram point (its state and period) or the fields' Ω from rest. */
async function showOrbit(rowIndex) {
  const t0 = performance.now();
  clearErrors($("orbit-panel"));
  let v;
  let request = {};
  try {
    // a diagram point's orbit is of the diagram's model, whatever the fields say since
    v = rowIndex !== undefined && rowIndex >= 0 ? { ...state.diagram.values } : dynValues();
    if (rowIndex !== undefined && rowIndex >= 0) {
      const r = state.rows[rowIndex];
      state.selected = rowIndex;
      $("orbit-omega").value = String(r.value);
      $("orbit-period").value = r.period ? String(r.period) : "";
      request = { initial: r.state };
      if (r.period) request.period = r.period;
    } else {
      const period = numberField("orbit-period", "period");
      if (period !== undefined) request.period = period;
    }
    v.omega = numberField("orbit-omega", "omega");
  } catch (e) {
    reportError(e, dynErrorPlaces("orbit"), $("err-orbit"));
    return;
  }
  const model = dynModel(v);
  const gen = ++generation.orbit;
  state.busy.orbit = true;
  status($("dyn-status"), "shooting the orbit…");
  try {
    const pending = engine.run("orbit", "orbit", { model, request });
    // the selection drawn while the worker shoots the orbit
    drawSelection();
    const { doc, ms } = await pending;
    state.timings.orbit_engine_ms = ms;
    state.orbit = doc;
    state.orbitRequest = { model, request };
    drawOrbit();
    state.timings.orbit_ms = performance.now() - t0;
    const spp = 200;
    const { doc: series } = await engine.run("orbit", "simulate", {
      model, request: { initial: doc.state, periods: doc.period, samples_per_period: spp },
    });
    state.series = { ...series, samples_per_period: spp };
    drawSeries();
    state.timings.orbit_view_ms = performance.now() - t0;
    status($("dyn-status"),
      `orbit at Ω = ${v.omega}: period ${doc.period}, ${doc.stable ? "stable" : "unstable"}; ` +
      `shown in ${state.timings.orbit_ms.toFixed(0)} ms (with its time series ${state.timings.orbit_view_ms.toFixed(0)} ms)`);
    writeHash();
  } catch (e) {
    reportError(e, dynErrorPlaces("orbit"), $("err-orbit"));
  } finally {
    if (gen === generation.orbit) state.busy.orbit = false;
  }
}

async function showModes() {
  clearErrors($("dyn-form"));
  let v;
  try {
    v = dynValues();
  } catch (e) {
    reportError(e, dynErrorPlaces("diagram"), $("err-dyn"));
    return;
  }
  try {
    const { doc } = await engine.run("orbit", "modes", { model: dynModel(v) });
    state.modes = doc;
    const t = $("modes-table");
    const cap = t.querySelector("caption");
    t.replaceChildren(cap);
    const head = t.insertRow();
    for (const h of ["mode", "free ω", "free λ", "contact ω", "contact λ"]) {
      const th = document.createElement("th");
      th.scope = "col";
      th.textContent = h;
      head.append(th);
    }
    const lam = ([re, im]) => `${re.toFixed(5)} ± ${im.toFixed(5)}i`;
    doc.free.omega.forEach((w, i) => {
      const row = t.insertRow();
      for (const c of [String(i + 1), w.toFixed(5), lam(doc.free.eigenvalues[i]),
        doc.contact.omega[i].toFixed(5), lam(doc.contact.eigenvalues[i])]) row.insertCell().textContent = c;
    });
    $("modes-panel").hidden = false;
  } catch (e) {
    reportError(e, dynErrorPlaces("diagram"), $("err-dyn"));
  }
}

function moveSelection(step) {
  if (!state.rows.length) return;
  const cur = state.rows[state.selected] ?? state.rows[0];
  const same = state.rows
    .map((r, i) => [r, i])
    .filter(([r]) => r.branch === cur.branch)
    .sort((a, b) => a[0].value - b[0].value || a[0].point - b[0].point);
  const at = Math.max(0, same.findIndex(([, i]) => i === state.selected));
  const next = same[Math.min(same.length - 1, Math.max(0, at + step))];
  state.selected = next[1];
  $("orbit-omega").value = String(next[0].value);
  drawSelection();
  status($("dyn-status"), `selected Ω = ${next[0].value} (${next[0].branch}, point ${next[0].point + 1} of ${next[0].points}); Enter shows its orbit`);
}

// ---------------------------------------------------------------------------- AFM

/** The probe file's text as a table, or null with the TOML parser's message shown. */
function probeObject() {
  try {
    return parseToml($("probe-text").value);
  } catch (e) {
    showError($("err-probe"), `probe: ${e.message.split("\n")[0]}`);
    return null;
  }
}

function getKey(obj, key) {
  return key.split(".").reduce((o, k) => (o && typeof o === "object" ? o[k] : undefined), obj);
}

function setKey(obj, key, value) {
  const path = key.split(".");
  let o = obj;
  for (const k of path.slice(0, -1)) {
    if (typeof o[k] !== "object" || o[k] === null) o[k] = {};
    o = o[k];
  }
  if (value === undefined) delete o[path.at(-1)];
  else o[path.at(-1)] = value;
}

/** The probe's fields from the probe file's text (a lever from the library fills the keys the
 * file leaves out; its values are shown as placeholders). */
function fieldsFromProbe() {
  const obj = probeObject();
  if (!obj) return;
  const lever = state.cantilevers.find((c) => c.name === getKey(obj, "cantilever.name"));
  $("cantilever").value = lever ? lever.name : "";
  for (const input of document.querySelectorAll("#afm-form [data-key]")) {
    const v = getKey(obj, input.dataset.key);
    input.value = v === undefined ? "" : showNumber(v);
    const fromLever = lever && { "cantilever.spring_constant": lever.spring_constant,
      "cantilever.resonance_frequency": lever.resonance_frequency,
      "cantilever.quality_factor": lever.quality_factor, "tip.radius": lever.radius }[input.dataset.key];
    input.placeholder = fromLever !== undefined ? `${fromLever} (${lever.name})` : "";
  }
}

/** A probe value as a field shows it: 4e9 rather than 4000000000. */
function showNumber(v) {
  if (typeof v !== "number") return String(v);
  const a = Math.abs(v);
  return a >= 1e5 || (a > 0 && a < 1e-3) ? v.toExponential().replace("e+", "e") : String(v);
}

/** A field edited: its key written into the probe file's text. */
function probeFromField(input) {
  const obj = probeObject();
  if (!obj) return;
  const raw = input.value.trim();
  let value;
  if (input.tagName === "SELECT") value = raw;
  else if (raw !== "") {
    value = Number(raw);
    if (!Number.isFinite(value)) {
      showError(input.parentElement.querySelector(".error"), `${input.dataset.key} = ${raw}: not a number`);
      return;
    }
  }
  setKey(obj, input.dataset.key, value);
  $("probe-text").value = stringifyToml(obj);
  probeChanged();
}

function chooseCantilever() {
  const obj = probeObject();
  if (!obj) return;
  const name = $("cantilever").value;
  if (name) {
    // the library's lever fills what the file leaves out: drop the file's own values
    obj.cantilever = { ...(obj.cantilever ?? {}), name };
    for (const k of ["spring_constant", "resonance_frequency", "quality_factor"]) delete obj.cantilever[k];
    if (obj.tip) delete obj.tip.radius;
  } else if (obj.cantilever) delete obj.cantilever.name;
  $("probe-text").value = stringifyToml(obj);
  fieldsFromProbe();
  probeChanged();
}

function choosePreset() {
  const p = state.presets.find((x) => x.file === $("probe-preset").value);
  if (p) {
    $("probe-text").value = p.text;
    fieldsFromProbe();
  }
}

function chooseSample() {
  const p = state.presets.find((x) => x.file === $("sample-preset").value);
  if (p) $("sample-text").value = p.text;
}

/** The example menu of `kind` ("probe", "sample") names the example whose text the file's text
 * is, else "(edited)": a menu never names an example the text no longer is (and choosing that
 * example again restores it). */
function presetOfText(kind) {
  const text = $(`${kind}-text`).value;
  const p = state.presets.find((x) => x.kind === kind && x.text === text);
  $(`${kind}-preset`).value = p ? p.file : "";
}

/** The probe's text changed: the example menu follows it (presetOfText), and the engine gives
 * its model's modes (`modes` of the probe: the document's "si" block), whose first mode's
 * frequency and quality factor are shown under the probe — in a fluid, the wet f₀ and Q
 * (Sader's hydrodynamic loading, the "medium" block), not the file's. */
async function probeChanged() {
  presetOfText("probe");
  const text = $("probe-text").value;
  const el = $("probe-modes");
  el.textContent = "";
  const g = (x, unit = "") => (typeof x === "number" ? `${x.toPrecision(6)}${unit}` : "— (overdamped)");
  try {
    const { doc } = await engine.run("probe", "modes", { probe: text });
    const si = doc.si;
    const m = si.medium;
    state.probeModes = { text, si };
    el.textContent = m
      ? `In ${m.name ?? "the fluid"} (ρ = ${m.density} kg/m³, η = ${m.viscosity} Pa s), the model's first mode: ` +
        `f₀ = ${g(m.resonance_frequency, " Hz")}, Q = ${g(m.quality_factor)} (wet; in vacuum f₀ = ${g(m.vacuum_resonance_frequency, " Hz")}; ` +
        `the file's f₀ and Q are those measured in ${m.calibrated_in})`
      : `The model's first mode: f₀ = ${g(si.free_frequencies_hz[0], " Hz")}, Q = ${g(si.quality_factors?.[0])}`;
  } catch (e) {
    // a probe the engine refuses: its message is shown beside its field when a curve is asked
    if (!(e instanceof Cancelled)) state.probeModes = { text, error: e.message };
  }
}

/** The fields an analysis takes: the sample map for an image, the setpoint for approach and
 * image, the points for the curves. */
function showAnalysisFields() {
  const a = $("afm-analysis").value;
  $("sample-box").hidden = a !== "image";
  $("setpoint").disabled = !(a === "approach" || a === "image");
  // a PeakForce image holds the peak force (N), an AM image and curve the amplitude ratio
  const pf = a === "image" && $("image-mode").value === "peakforce";
  $("setpoint-label").textContent = pf ? "setpoint: peak force (N)" : "setpoint A/A₀";
  $("feedback").disabled = pf;
  // (a PeakForce tap is one steady orbit at the probe's z_c: no curve)
  $("points").disabled = a === "image" || a === "peakforce";
  // the swept range: z_c (m), or the drive frequency (Hz) of a resonance curve
  for (const end of ["from", "to"]) {
    $(`curve-${end}`).disabled = a === "image" || a === "peakforce";
    $(`curve-${end}-label`).textContent = a === "resonance" ? `frequency ${end} (Hz)` : `z_c ${end} (m)`;
  }
  $("fm-amplitude").disabled = a !== "fm";
}

/** The element of a request key's message in the AFM form. */
const AFM_ERRORS = { from: "err-curve-from", to: "err-curve-to", amplitude: "err-fm-amplitude" };
const afmErrorOf = (name) => $(AFM_ERRORS[name] ?? `err-${name}`);

function afmErrorPlaces(message) {
  const placed = probeErrors(message, (key) =>
    document.querySelector(`#afm-form [data-key="${key}"]`)?.parentElement.querySelector(".error"), $("err-probe"));
  if (placed.length) return placed;
  return fieldErrors(message, afmErrorOf);
}

function afmRequest() {
  const analysis = $("afm-analysis").value;
  const request = {};
  const put = (key, id) => {
    const v = numberField(id, key);
    if (v !== undefined) request[key] = v;
  };
  if (analysis === "image") {
    put("setpoint", "setpoint");
    put("pixels", "pixels");
    put("lines", "lines");
    if ($("image-mode").value === "peakforce") {
      // the ideal peak-force feedback (its only one): the setpoint is the peak force in N
      request.mode = "peakforce";
    } else {
      // the engine says why a PI scan is not run here (its message beside the field)
      request.feedback = $("feedback").value;
    }
  } else if (analysis !== "peakforce") {
    put("points", "points");
    put("from", "curve-from");
    put("to", "curve-to");
    if (analysis === "approach") put("setpoint", "setpoint");
    if (analysis === "fm") put("amplitude", "fm-amplitude");
  }
  return { analysis, request };
}

async function runAfm() {
  const form = $("afm-form");
  clearErrors(form);
  let req;
  try {
    req = afmRequest();
  } catch (e) {
    reportError(e, (m) => fieldErrors(m, afmErrorOf), $("err-afm"));
    return;
  }
  writeHash();
  const input = { probe: $("probe-text").value, request: req.request };
  const gen = ++generation.afm;
  if (req.analysis === "image") input.sample = $("sample-text").value;
  state.busy.afm = true;
  const what = { image: "image", peakforce: "steady tap" }[req.analysis] ?? `${req.analysis} curve`;
  status($("afm-status"), `computing the ${what}…`);
  const t0 = performance.now();
  try {
    const { doc, ms } = await engine.run("afm", req.analysis, input);
    state.afm = { analysis: req.analysis, doc, input };
    if (req.analysis === "fm") {
      // the force behind the curve: the library reads the fm document (its distances, shifts,
      // k, f₀ and A) as `afmdyn reconstruct --fm fm.json` does
      try {
        state.afm.reconstruction = (await engine.run("afm", "reconstruct_fm", doc)).doc;
      } catch (e) {
        if (e instanceof Cancelled) throw e;
        state.afm.reconstruction = { error: e.message };
      }
    }
    state.timings.afm_ms = performance.now() - t0;
    state.timings.afm_engine_ms = ms;
    drawAfmDocument(state.afm, $("afm-y").value);
    status($("afm-status"), `${what} in ${(state.timings.afm_ms / 1000).toFixed(2)} s` +
      (doc.warnings?.length ? ` — ${doc.warnings.length} warning(s) below` : ""));
  } catch (e) {
    reportError(e, afmErrorPlaces, $("err-afm"));
    if (!(e instanceof Cancelled)) status($("afm-status"), "");
  } finally {
    if (gen === generation.afm) state.busy.afm = false;
  }
}

// ---------------------------------------------------------------------------- export


// ---------------------------------------------------------------------------- wiring

function selectTab(name) {
  for (const [tab, ws] of [["tab-dyn", "ws-dyn"], ["tab-afm", "ws-afm"]]) {
    const on = tab === name;
    $(tab).setAttribute("aria-selected", String(on));
    $(tab).tabIndex = on ? 0 : -1;
    $(ws).hidden = !on;
  }
  // plots drawn while hidden have no size
  window.dispatchEvent(new Event("resize"));
}

async function loadPresets() {
  const index = await (await fetch("presets/index.json")).json();
  state.presets = await Promise.all(index.map(async (p) => ({ ...p, text: await (await fetch(`presets/${p.file}`)).text() })));
  for (const p of state.presets) $(`${p.kind}-preset`).add(new Option(`${p.file} — ${p.title}`, p.file));
}

function applyHash(p) {
  for (const f of DYN_FIELDS) if (p.has(f)) $(f).value = p.get(f);
  for (const [k, id] of [["y", "bif-y"], ["omega", "orbit-omega"], ["period", "orbit-period"],
    ...AFM_KEPT.map((k) => [k, k]), ["sample", "sample-preset"]]) {
    if (p.has(k)) $(id).value = p.get(k);
  }
  if (p.has("probe")) $("probe-preset").value = p.get("probe");
  choosePreset();
  chooseSample();
  if (p.has("sampletext")) $("sample-text").value = p.get("sampletext");
  showAnalysisFields();
  if (p.has("probetext")) $("probe-text").value = p.get("probetext");
  if (p.has("cantilever")) {
    $("cantilever").value = p.get("cantilever");
    if (!p.has("probetext")) chooseCantilever();
  }
  fieldsFromProbe();
  probeChanged();
  presetOfText("sample");
}

async function main() {
  for (const p of DYN_PRESETS) $("dyn-preset").add(new Option(p.label, p.id));
  engine = await Engine.load("pkg/afmdyn_wasm_bg.wasm", "worker.js");
  // testing: hold results back so that a request is certainly running (Engine.hold)
  window.explorer.hold = (on) => engine.hold(on);
  const presets = loadPresets();
  // the engine's data, one after the other on one worker, which then ends
  const { doc: version } = await engine.run("meta", "version", {});
  const { doc: levers } = await engine.run("meta", "cantilevers", {});
  const { doc: laws } = await engine.run("meta", "laws", {});
  state.columns = (await engine.run("meta", "bifurcation_columns", {})).doc;
  engine.close("meta");
  await presets;
  $("version").textContent = `Library version ${version}.`;
  // both law lists from the library's registry (the model's and the probe's sample)
  for (const id of ["contact_law", "p-law"]) for (const l of laws) $(id).add(Object.assign(new Option(l.name, l.name), { title: l.doc }));
  state.cantilevers = levers.cantilevers;
  for (const c of state.cantilevers) $("cantilever").add(new Option(`${c.name} (${c.maker}: k = ${c.spring_constant} N/m, f₀ = ${c.resonance_frequency / 1e3} kHz, Q = ${c.quality_factor})`, c.name));
  const defaultProbe = state.presets.find((x) => x.file === "probe-point-mass-dmt.toml") ?? state.presets[0];
  $("probe-preset").value = defaultProbe.file;
  $("sample-preset").value = "sample-stripe.toml";

  const hash = readHash();
  applyHash(hash);

  $("dyn-form").addEventListener("submit", (e) => { e.preventDefault(); runDiagram(); });
  $("dyn-preset").addEventListener("change", () => {
    const p = DYN_PRESETS.find((x) => x.id === $("dyn-preset").value);
    for (const [k, v] of Object.entries(p.values)) $(k).value = String(v);
    if (p.modesOnly) showModes();
    else runDiagram();
  });
  $("bif-y").addEventListener("change", () => { drawDiagram(); writeHash(); });
  $("modes-run").addEventListener("click", showModes);
  $("orbit-run").addEventListener("click", () => { state.selected = -1; showOrbit(); });
  const plot = $("bif-plot");
  plot.addEventListener("keydown", (e) => {
    if (e.key === "ArrowRight" || e.key === "ArrowUp") { moveSelection(1); e.preventDefault(); }
    else if (e.key === "ArrowLeft" || e.key === "ArrowDown") { moveSelection(-1); e.preventDefault(); }
    else if (e.key === "Enter" && state.selected >= 0) { showOrbit(state.selected); e.preventDefault(); }
  });
  drawDiagram();
  plot.on("plotly_relayout", drawSelection);
  plot.on("plotly_click", (ev) => {
    const pt = ev.points.find((x) => x.customdata !== undefined);
    if (pt) showOrbit(pt.customdata);
  });

  for (const input of document.querySelectorAll("#afm-form [data-key]")) {
    input.addEventListener("change", () => { clearErrors($("afm-form")); probeFromField(input); });
  }
  $("probe-text").addEventListener("change", () => { clearErrors($("afm-form")); fieldsFromProbe(); probeChanged(); });
  $("probe-preset").addEventListener("change", () => { clearErrors($("afm-form")); choosePreset(); probeChanged(); });
  $("sample-text").addEventListener("change", () => presetOfText("sample"));
  $("cantilever").addEventListener("change", () => { clearErrors($("afm-form")); chooseCantilever(); });
  $("afm-form").addEventListener("submit", (e) => { e.preventDefault(); runAfm(); });
  let swept = $("afm-analysis").value === "resonance";
  $("afm-analysis").addEventListener("change", () => {
    // a range in Hz is no range of z_c (m), nor the reverse: blanked when the swept quantity
    // changes
    const hz = $("afm-analysis").value === "resonance";
    if (hz !== swept) for (const id of ["curve-from", "curve-to"]) $(id).value = "";
    swept = hz;
    showAnalysisFields();
  });
  $("sample-preset").addEventListener("change", chooseSample);
  $("image-mode").addEventListener("change", showAnalysisFields);
  $("afm-y").addEventListener("change", () => { if (state.afm) drawAfmDocument(state.afm, $("afm-y").value); writeHash(); });

  for (const b of document.querySelectorAll("[data-export]")) {
    b.addEventListener("click", () => exportData(state, b.dataset.export, b.dataset.what));
  }
  for (const b of document.querySelectorAll("[data-share]")) {
    b.addEventListener("click", async () => {
      writeHash();
      try { await navigator.clipboard.writeText(location.href); b.textContent = "Link copied"; } catch { b.textContent = "Link in the address bar"; }
    });
  }
  const tabs = [$("tab-dyn"), $("tab-afm")];
  for (const t of tabs) {
    t.addEventListener("click", () => { selectTab(t.id); writeHash(); });
    t.addEventListener("keydown", (e) => {
      if (e.key === "ArrowRight" || e.key === "ArrowLeft") {
        const other = tabs.find((x) => x !== t);
        selectTab(other.id);
        other.focus();
        writeHash();
      }
    });
  }

  // the lanes' workers started now, so that a click finds its module instantiated
  for (const lane of ["orbit", "afm", "probe"]) engine.lane(lane);
  state.ready = true;
  if (hash.get("ws") === "afm") {
    selectTab("tab-afm");
    runAfm();
  } else {
    runDiagram();
  }
}

main().catch((e) => {
  document.body.insertAdjacentHTML("afterbegin", `<p class="fatal" role="alert"></p>`);
  document.querySelector(".fatal").textContent = `The engine could not start: ${e.message}`;
  console.error(e);
});
