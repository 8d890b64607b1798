// afmdyn explorer: the page. It maps form fields to the engine's requests (the JSON the
// WebAssembly build of the library reads: crates/afmdyn-wasm, docs/browser.md) and draws the
// documents it returns. No numerics live here: every number shown is the library's, the same as
// `afmdyn … --json`.
import Plotly from "plotly.js-cartesian-dist-min";
import { parse as parseToml, stringify as stringifyToml } from "smol-toml";
import { Engine, Cancelled } from "./engine.js";
import { fieldErrors, probeErrors } from "./errors.js";
import { DYN_PRESETS, DYN_FIELDS, dynModel, dynRequest } from "./dynamics.js";
import { toCsv, download } from "./export.js";
import { peakforceView, peakforceRows } from "./peakforce.js";

const $ = (id) => document.getElementById(id);
const COLOURS = { forward: "#1f5fbf", backward: "#c0392b", selected: "#f39c12" };
const PLOT_CONFIG = { responsive: true, displaylogo: false };

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
const AFM_KEPT = ["afm-analysis", "points", "setpoint", "afm-y", "pixels", "lines", "feedback", "curve-from", "curve-to", "fm-amplitude"];

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

function summary(el, entries) {
  el.replaceChildren();
  for (const [k, v] of entries) {
    const dt = document.createElement("dt");
    dt.textContent = k;
    const dd = document.createElement("dd");
    dd.textContent = v;
    el.append(dt, dd);
  }
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
    // the engine says why a PI scan is not run here (its message beside the field)
    request.feedback = $("feedback").value;
  } else if (analysis !== "peakforce") {
    put("points", "points");
    put("from", "curve-from");
    put("to", "curve-to");
    if (analysis === "approach") put("setpoint", "setpoint");
    if (analysis === "fm") put("amplitude", "fm-amplitude");
  }
  return { analysis, request };
}

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

const AXIS_UNITS = { amplitude: "m", z_c: "m", peak_force: "N", indentation: "m", energy_dissipated: "J", virial: "J", phase_deg: "°", frequency_hz: "Hz", frequency_shift: "Hz" };
const AXIS_NAMES = { amplitude: "amplitude A", z_c: "z_c (rest tip–sample distance)", peak_force: "peak force", indentation: "indentation", energy_dissipated: "E_dis (dissipated energy per period)", virial: "virial", phase_deg: "phase", frequency_hz: "drive frequency", frequency_shift: "frequency shift Δf" };
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

function drawAfm() {
  const d = state.afm.doc;
  const kind = state.afm.analysis;
  const y = $("afm-y").value;
  // the reconstruction's plot, shown before it is drawn (a plot drawn hidden has no size)
  $("afm-plot-c").hidden = !(kind === "fm" && state.afm.reconstruction?.force);
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
    const r = state.afm.reconstruction;
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
  const rec = kind === "fm" ? state.afm.reconstruction : null;
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
  const key = im[channel] ? channel : "phase_deg";
  const margin = { l: 75, r: 10, t: 30, b: 50 };
  const xTitle = { title: { text: "x (m)" }, exponentformat: "SI" };
  if (im.y.length === 1) {
    react("afm-plot-a", [
      lines(im.x, im.height[0], "apparent height", COLOURS.forward),
      lines(im.x, im.true_height[0], "true height", "#7f8c8d", { line: { dash: "dot", color: "#7f8c8d" } }),
    ], { margin, title: { text: `Line profile at A/A₀ = ${d.setpoint}`, font: { size: 13 } }, xaxis: xTitle,
      yaxis: { title: { text: "height (m)" }, exponentformat: "SI" }, legend: { orientation: "h", y: -0.25 } });
    react("afm-plot-b", [lines(im.x, im[key][0], AXIS_NAMES[key], COLOURS.backward)],
      { margin, title: { text: AXIS_NAMES[key], font: { size: 13 } }, xaxis: xTitle,
        yaxis: axis(key), legend: { orientation: "h", y: -0.25 } });
  } else {
    const heat = (div, z, name, unit) => Plotly.react(div, [{
      type: "heatmap", x: im.x, y: im.y, z, colorscale: "Viridis",
      colorbar: { title: { text: `${name} (${unit})` }, exponentformat: "SI" },
    }], { margin: { ...margin, r: 20 }, title: { text: `${name} at A/A₀ = ${d.setpoint}`, font: { size: 13 } },
      xaxis: xTitle, yaxis: { title: { text: "y (m)" }, exponentformat: "SI", scaleanchor: "x" } }, PLOT_CONFIG);
    heat("afm-plot-a", im.height, "apparent height", "m");
    heat("afm-plot-b", im[key], AXIS_NAMES[key], AXIS_UNITS[key]);
  }
  summary($("afm-summary"), [
    ["feedback", d.feedback],
    ["setpoint", `A/A₀ = ${d.setpoint}`],
    ["pixels", `${im.x.length} × ${im.y.length}`],
    ["reference z_c", `${d.reference_z_c.toExponential(4)} m`],
  ]);
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
    drawAfm();
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

function exportData(format, what) {
  if (what === "dyn") {
    if (format === "csv") {
      // bifurcation.csv's columns (afmdyn::request::sweep::COLUMNS), the state space-separated
      const rows = state.rows.map((r) => Object.fromEntries(state.columns.map(({ name: c }) =>
        [c, c === "state" ? r.state.join(" ") : r[c]])));
      download("bifurcation.csv", toCsv(rows), "text/csv");
    } else {
      download("orbit.json", JSON.stringify({ request: state.orbitRequest, orbit: state.orbit, series: state.series?.series }, null, 1), "application/json");
    }
  } else if (what === "afm") {
    if (!state.afm) return;
    if (format === "json") download(`${state.afm.analysis}.json`, JSON.stringify(state.afm.doc, null, 1), "application/json");
    else {
      const d = state.afm.doc;
      const a = state.afm.analysis;
      if (a === "image") {
        // one row per pixel: line, pixel, x, y and every map's value there
        const im = d.image;
        const maps = Object.keys(im).filter((k) => k !== "x" && k !== "y");
        const rows = im.y.flatMap((y, j) => im.x.map((x, i) => ({ line: j, pixel: i, x, y,
          ...Object.fromEntries(maps.map((k) => [k, im[k][j][i]])) })));
        download("image.csv", toCsv(rows), "text/csv");
        return;
      }
      if (a === "peakforce") {
        download("peakforce-cycle.csv", toCsv(peakforceRows(d)), "text/csv");
        return;
      }
      const sweeps = a === "approach" || a === "bimodal" ? { approach: d.approach, retract: d.retract }
        : a === "resonance" ? { up: d.up, down: d.down } : { curve: d.curve };
      const rows = [];
      for (const [name, s] of Object.entries(sweeps)) {
        const keys = Object.keys(s);
        s[keys[0]].forEach((_, i) => rows.push({ sweep: name, ...Object.fromEntries(keys.map((k) => [k, s[k][i]])) }));
      }
      download(`${state.afm.analysis}.csv`, toCsv(rows), "text/csv");
    }
  } else {
    Plotly.downloadImage(what, { format, filename: what, width: 1000, height: 600 });
  }
}

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
  $("afm-y").addEventListener("change", () => { if (state.afm) drawAfm(); writeHash(); });

  for (const b of document.querySelectorAll("[data-export]")) {
    b.addEventListener("click", () => exportData(b.dataset.export, b.dataset.what));
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
