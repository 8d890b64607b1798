// The explorer in a real browser (issue 47; run by scripts/test-explorer.sh, part of the README's
// test command): headless Debian Chromium driven by playwright-core against the built site served
// on 127.0.0.1. Every number the page shows is checked against the native command line's
// (`afmdyn … --json`, the binary given) at the same parameters.
//   node explorer/tests/browser.mjs --url URL --bin AFMDYN --chromium PATH --out DIR
// Prints each check, the timings (diagram, click to orbit, approach curve) and
// "explorer: N passed, M failed" last; saves DIR/screenshot.png (and screenshot-afm.png).
import { chromium } from "playwright-core";
import { execFileSync, spawnSync } from "node:child_process";
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { worst, approachSweeps, approachBranches, branchesScaled, compareBifurcation, imageAgainstSummary,
  peakforceAgainstSummary } from "../../scripts/compare-docs.mjs";

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../..");
const arg = (name) => {
  const i = process.argv.indexOf(name);
  if (i < 0) throw new Error(`missing ${name}`);
  return process.argv[i + 1];
};
const url = arg("--url");
const bin = path.resolve(arg("--bin"));
const out = path.resolve(arg("--out"));
let passed = 0, failed = 0;
const timings = {};

function check(name, ok, detail = "") {
  if (ok) { passed += 1; console.log(`ok   ${name}`); }
  else { failed += 1; console.log(`FAIL ${name} ${detail}`); }
}
function native(args) {
  return JSON.parse(execFileSync(bin, [...args, "--json"], { cwd: root, encoding: "utf8", stdio: ["ignore", "pipe", "pipe"] }));
}
/** The command line's one-line message for `args` (stderr without the "afmdyn: " prefix). */
function nativeError(args) {
  const r = spawnSync(bin, args, { cwd: root, encoding: "utf8" });
  return r.stderr.trim().replace(/^afmdyn: /, "");
}

const browser = await chromium.launch({
  executablePath: arg("--chromium"),
  headless: true,
  // the machine's network is closed: no background connections, no component updates
  args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
const browserVersion = browser.version();
const errors = [];
// the command line's output directories, removed at the end
const scratch = [];
const scratchDir = () => {
  const d = mkdtempSync(path.join(tmpdir(), "afmdyn-explorer-"));
  scratch.push(d);
  return d;
};
try {
  const context = await browser.newContext({ viewport: { width: 1440, height: 900 }, acceptDownloads: true });
  const page = await context.newPage();
  page.on("pageerror", (e) => errors.push(`page error: ${e.message}`));
  page.on("console", (m) => { if (m.type() === "error") errors.push(`console: ${m.text()}`); });
  page.setDefaultTimeout(120_000);

  // ------------------------------------------------------------------ the default diagram
  const t0 = Date.now();
  await page.goto(url);
  await page.waitForFunction(() => window.explorer?.ready);
  check("the page loads and shows the library's version",
    /Library version \d+\.\d+\.\d+/.test(await page.textContent("#version")));
  // the page starts the default Fig. 5 diagram itself
  await page.waitForFunction(() => window.explorer.timings.diagram_ms !== undefined);
  timings.diagram = await page.evaluate(() => window.explorer.timings.diagram_ms);
  timings.load_and_diagram = Date.now() - t0;
  const rows = await page.evaluate(() => window.explorer.rows);
  const tmp = scratchDir();
  execFileSync(bin, ["bifurcation", "--out", tmp], { cwd: root });
  const csvText = readFileSync(path.join(tmp, "bifurcation.csv"), "utf8");
  const cmp = compareBifurcation(rows, csvText);
  // each run stops its transient when two returns repeat to 1e-8, which leaves it up to
  // 1e-8 |μ|/(1 − |μ|) from the cycle; the sweep passes points with |μ| = 0.988 (Ω = 2.504,
  // backward: 5.5e-7 from the shot orbit), and wasm's last bits may stop a period earlier or
  // later: the cycles agree to 1e-5, not to the 1e-6 of a short sweep
  check("the default diagram (Fig. 5, 400 Ω values each way) is `afmdyn bifurcation`'s " +
    "bifurcation.csv (rows, statuses; periodic cycles to 1e-5)", !cmp.bad && cmp.far <= 1e-5,
  cmp.bad || `${cmp.far}`);
  console.log(`     ${cmp.rows} rows, ${cmp.periodic} periodic points; largest difference ${cmp.far.toExponential(1)} (value index, branch: ${cmp.farAt})`);
  const drawn = await page.evaluate(() => {
    const gd = document.getElementById("bif-plot");
    return { n: gd.data.slice(0, 2).reduce((s, t) => s + t.x.length, 0), x: gd.layout.xaxis.title.text };
  });
  check("every Poincaré point is drawn, the Ω axis labelled", drawn.n === rows.filter((r) => r.x_max !== null).length && /Ω/.test(drawn.x),
    JSON.stringify(drawn));

  // ------------------------------------------------------------------ click a point → orbit
  // a periodic point on the forward branch near Ω = 2.8: its pixel from the plot's own axes
  const target = rows.findIndex((r) => r.branch === "forward" && r.status === "periodic" && r.value >= 2.8);
  const at = await page.evaluate((i) => {
    const gd = document.getElementById("bif-plot");
    const r = window.explorer.rows[i];
    const L = gd._fullLayout;
    const box = gd.querySelector(".nsewdrag").getBoundingClientRect();
    const y = document.getElementById("bif-y").value;
    return { x: box.left + L.xaxis.l2p(r.value), y: box.top + L.yaxis.l2p(r[y]) };
  }, target);
  const before = await page.evaluate(() => window.explorer.timings.orbit_view_ms);
  await page.mouse.move(at.x, at.y);
  await page.mouse.click(at.x, at.y);
  await page.waitForFunction((b) => window.explorer.timings.orbit_view_ms !== b && !window.explorer.busy.orbit, before);
  const shown = await page.evaluate(() => ({
    selected: window.explorer.selected, orbit: window.explorer.orbit, series: window.explorer.series,
    summary: document.getElementById("orbit-summary").textContent, t: window.explorer.timings,
  }));
  timings.click_to_orbit = shown.t.orbit_ms;
  timings.click_to_orbit_view = shown.t.orbit_view_ms;
  timings.orbit_engine = shown.t.orbit_engine_ms;
  check("a click on the diagram selects a point", shown.selected >= 0, String(shown.selected));
  const row = rows[shown.selected] ?? rows[target];
  const n = row.state.length / 2;
  const modal = `${row.state.slice(0, n).join(",")};${row.state.slice(n).join(",")}`;
  const ref = native(["orbit", "--omega", String(row.value), "--initial-modal", modal,
    ...(row.period ? ["--period", String(row.period)] : [])]);
  check(`the clicked point's orbit (Ω = ${row.value}) has the period of \`afmdyn orbit --json\` there`,
    shown.orbit.period === ref.period, `${shown.orbit.period} vs ${ref.period}`);
  const [wp, atp] = worst(shown.orbit.poincare, ref.poincare);
  check("… and its Poincaré points (to 1e-9)", wp <= 1e-9, `${wp} at ${atp}`);
  const [wm] = worst(shown.orbit.multipliers, ref.multipliers);
  check("… and its Floquet multipliers (to 1e-9) and stability", wm <= 1e-9 && shown.orbit.stable === ref.stable, `${wm}`);
  console.log(`     Poincaré points differ by ${wp.toExponential(1)}, multipliers by ${wm.toExponential(1)}`);
  check("the orbit's period and stability are shown", shown.summary.includes(`${ref.period} drive period`) &&
    shown.summary.includes(ref.stable ? "yes" : "no"), shown.summary.slice(0, 120));
  const series = await page.evaluate(() => {
    const s = document.getElementById("orbit-series");
    const p = document.getElementById("orbit-phase");
    return { s: s.data?.[0]?.x.length ?? 0, p: p.data?.length ?? 0, xs: s.layout?.xaxis.title.text ?? "" };
  });
  const spp = shown.series.samples_per_period;
  check("its time series W(1, τ) over the period and its phase portrait are drawn",
    series.s === ref.period * spp + 1 && series.p === 2, JSON.stringify(series));
  // the series starts at the orbit's own state: W(1, 0) is its first Poincaré point
  const w0 = shown.series.series.w_tip?.values?.[0] ?? shown.series.series.w?.values?.[0];
  check("the time series starts on the orbit's first Poincaré point (to 1e-9)",
    Math.abs(w0 - ref.poincare.w_tip[0]) <= 1e-9 * (1 + Math.abs(ref.poincare.w_tip[0])), `${w0} vs ${ref.poincare.w_tip[0]}`);
  await page.screenshot({ path: path.join(out, "screenshot.png"), fullPage: true });

  // keyboard: the diagram takes focus, → moves the selection, Enter shows that orbit
  // a field changed since the diagram was computed does not change its points' orbits
  await page.fill("#alpha1", "0.2");
  await page.focus("#bif-plot");
  const sel0 = await page.evaluate(() => window.explorer.selected);
  await page.keyboard.press("ArrowRight");
  const sel1 = await page.evaluate(() => window.explorer.selected);
  const before2 = await page.evaluate(() => window.explorer.timings.orbit_view_ms);
  await page.keyboard.press("Enter");
  await page.waitForFunction((b) => window.explorer.timings.orbit_view_ms !== b && !window.explorer.busy.orbit, before2);
  const kb = await page.evaluate(() => ({ r: window.explorer.rows[window.explorer.selected], o: window.explorer.orbitRequest }));
  check("keyboard: → moves the selected point and Enter shows its orbit, of the diagram's model",
    sel1 !== sel0 && kb.o.model.omega === kb.r.value && kb.o.model.alpha1 === 0.1, `${sel0} → ${sel1}; α1 = ${kb.o.model.alpha1}`);
  await page.fill("#alpha1", "0.1");

  // the eigenfrequency view: the command line's natural frequencies (eqs. 19–23)
  await page.click("#modes-run");
  await page.waitForFunction(() => window.explorer.modes && !document.getElementById("modes-panel").hidden);
  const modes = await page.evaluate(() => ({ doc: window.explorer.modes, rows: document.querySelectorAll("#modes-table tr").length }));
  const refModes = native(["modes"]);
  const [wq] = worst(modes.doc, refModes);
  check("the eigenfrequency view is `afmdyn modes --json`'s (to 1e-9), a table row per mode",
    wq <= 1e-9 && modes.rows === refModes.free.omega.length + 1, `${wq}; ${modes.rows} rows`);

  // ------------------------------------------------------------------ export
  const [dl] = await Promise.all([page.waitForEvent("download"), page.click("[data-export=csv][data-what=dyn]")]);
  const exported = readFileSync(await dl.path(), "utf8").split("\n");
  const cliHead = csvText.split("\n")[0].split(",");
  const pageHead = exported[0].split(",");
  check("the diagram's CSV export has bifurcation.csv's columns and one line per point",
    pageHead.join(",") === cliHead.join(",") && exported.length - 2 === rows.length,
    `${pageHead.join(",")} vs ${cliHead.join(",")}; ${exported.length - 2} lines`);
  const [png] = await Promise.all([page.waitForEvent("download"), page.click("[data-export=png][data-what=bif-plot]")]);
  const pngBytes = readFileSync(await png.path());
  check("the diagram exports as PNG", pngBytes.subarray(1, 4).toString() === "PNG", String(pngBytes.length));
  const [svg] = await Promise.all([page.waitForEvent("download"), page.click("[data-export=svg][data-what=bif-plot]")]);
  check("the diagram exports as SVG", readFileSync(await svg.path(), "utf8").includes("<svg"));

  // ------------------------------------------------------------------ bad input
  await page.fill("#alpha1", "-1");
  await page.click("#dyn-run");
  await page.waitForFunction(() => document.getElementById("err-alpha1").textContent !== "");
  const msg = await page.textContent("#err-alpha1");
  const cliMsg = nativeError(["orbit", "--tip-mass-ratio", "-1"]);
  check("a bad α1 is refused beside its field with the command line's message",
    msg === cliMsg && await page.getAttribute("#alpha1", "aria-invalid") === "true", `"${msg}" vs "${cliMsg}"`);
  await page.fill("#alpha1", "0.1");
  await page.fill("#orbit-omega", "two");
  await page.click("#orbit-run");
  await page.waitForFunction(() => document.getElementById("err-omega").textContent !== "");
  check("text that is no number is refused beside its field, naming the key",
    await page.textContent("#err-omega") === "omega = two: must be a number", await page.textContent("#err-omega"));
  await page.fill("#orbit-omega", "2.8");

  // ------------------------------------------------------------------ AFM: approach from a preset
  await page.click("#tab-afm");
  await page.selectOption("#probe-preset", "probe-point-mass-dmt.toml");
  await page.fill("#points", "60");
  await page.fill("#setpoint", "0.7");
  const tA = await page.evaluate(() => window.explorer.timings.afm_ms);
  await page.click("#afm-run");
  await page.waitForFunction((b) => window.explorer.timings.afm_ms !== b && !window.explorer.busy.afm, tA);
  timings.approach = await page.evaluate(() => window.explorer.timings.afm_ms);
  const curve = await page.evaluate(() => window.explorer.afm.doc);
  const refCurve = native(["approach", "--probe", "examples/probe-point-mass-dmt.toml", "--points", "60", "--setpoint", "0.7", "--out", tmp]);
  let [w, where] = worst(approachSweeps(curve), approachSweeps(refCurve));
  check("the approach curve from the preset probe is `afmdyn approach --probe … --json`'s " +
    "(sweeps and setpoint to 1e-9)", w <= 1e-9, `${w} at ${where}`);
  console.log(`     largest difference ${w.toExponential(1)} at ${where}`);
  [w, where] = worst(approachBranches(curve), approachBranches(refCurve));
  check("… and its branches, folds and jumps (to 1e-6)", w <= 1e-6, `${w} at ${where}`);
  const axes = await page.evaluate(() => ["afm-plot-a", "afm-plot-b"].map((id) => {
    const gd = document.getElementById(id);
    return [gd.layout.xaxis.title.text, gd.layout.yaxis.title.text, gd.data.length];
  }));
  check("the curves are drawn with labelled SI axes (z_c in m, amplitude in m, phase in °)",
    axes[0][0].includes("(m)") && axes[0][1].includes("(m)") && axes[1][1].includes("(°)") && axes[0][2] >= 3,
    JSON.stringify(axes));
  const sumText = await page.textContent("#afm-summary");
  const op = refCurve.setpoint.points[0];
  check("the setpoint's operating point is shown (z_c, regime)", sumText.includes(op.z_c.toExponential(4)) && sumText.includes(op.regime),
    sumText.slice(0, 200));
  await page.screenshot({ path: path.join(out, "screenshot-afm.png"), fullPage: true });

  // a curve computed: its document
  const afmRun = async () => {
    const b = await page.evaluate(() => window.explorer.timings.afm_ms);
    await page.click("#afm-run");
    await page.waitForFunction((t) => window.explorer.timings.afm_ms !== t && !window.explorer.busy.afm, b);
    return page.evaluate(() => window.explorer.afm.doc);
  };
  // resonance and FM curves of the same probe against the command line's
  await page.selectOption("#afm-analysis", "resonance");
  await page.fill("#points", "40");
  const resonance = await afmRun();
  const refRes = native(["resonance", "--probe", "examples/probe-point-mass-dmt.toml", "--points", "40", "--out", tmp]);
  [w, where] = worst(approachSweeps(resonance), approachSweeps(refRes));
  const [wr, wrAt] = branchesScaled(resonance.branches, refRes.branches);
  // a sweep's steady state settles to the curve's tolerance (1e-10) at the free lever's decay
  // per period e^(−π/Q), so each run stops up to about 1e-10 Q/π from it, and two runs whose
  // last bits differ up to twice that: 2.5e-8 at Q = 400 (measured 5.0e-9 here; 2.1e-8 on the
  // RTESPA-300, Q = 500, bound 3.2e-8); the sweeps agree to 1e-7
  check("the resonance curve is `afmdyn resonance --json`'s (sweeps to 1e-7, branches to 1e-6, 1e-4 at events)",
    w <= 1e-7 && wr <= 1, `${w} at ${where}; ${wr} of the tolerance at ${wrAt}`);
  console.log(`     largest difference ${w.toExponential(1)} at ${where}`);
  await page.selectOption("#afm-analysis", "fm");
  await page.fill("#points", "20");
  const fm = await afmRun();
  const refFm = native(["fm", "--probe", "examples/probe-point-mass-dmt.toml", "--points", "20", "--out", tmp]);
  [w, where] = worst(fm.curve, refFm.curve);
  // the two loop conditions are solved by Newton's method to the request's tolerance, 1e-9
  check("the FM curve Δf(z_c) is `afmdyn fm --json`'s (to 1e-8: its loop solved to 1e-9), drawn against z_c",
    w <= 1e-8 && await page.evaluate(() => document.getElementById("afm-plot-a").layout.yaxis.title.text.includes("(Hz)")), `${w} at ${where}`);
  console.log(`     largest difference ${w.toExponential(1)} at ${where}`);
  // the force behind the curve: the page's own fm document through `afmdyn reconstruct --fm`
  const fmFile = path.join(tmp, "page-fm.json");
  writeFileSync(fmFile, JSON.stringify(fm));
  const refRec = native(["reconstruct", "--fm", fmFile, "--files", "none"]);
  const rec = await page.evaluate(() => ({ r: window.explorer.afm.reconstruction, n: document.getElementById("afm-plot-c").data?.length ?? 0,
    shown: !document.getElementById("afm-plot-c").hidden,
    // drawn at its box's width (not at Plotly's default for a plot drawn while hidden)
    fits: Math.abs(document.getElementById("afm-plot-c")._fullLayout.width - document.getElementById("afm-plot-c").clientWidth) <= 2,
    warned: [...document.querySelectorAll("#afm-warnings li")].map((li) => li.textContent) }));
  const scale = Math.max(...refRec.force.force.map(Math.abs));
  const farF = rec.r?.force ? Math.max(...rec.r.force.force.map((f, i) => Math.abs(f - refRec.force.force[i]) / scale)) : Infinity;
  check("the FM curve's force reconstruction is `afmdyn reconstruct --fm` of the page's fm document (force to 1e-9 of its extreme; distances, law, warnings), drawn with the law",
    farF <= 1e-9 && rec.r.force.force.length === refRec.force.force.length &&
    worst(rec.r.force.distance, refRec.force.distance)[0] <= 1e-12 && JSON.stringify(rec.r.force.law) === JSON.stringify(refRec.force.law) &&
    rec.shown && rec.fits && rec.n === 2 && refRec.warnings.every((m) => rec.warned.includes(`reconstruction: ${m}`)),
  `${farF}; ${rec.n} traces; fits its box: ${rec.fits}; ${JSON.stringify(rec.warned)}`);
  // the phase is held at 90° by the PLL: its spread is the loop's round-off, drawn flat with
  // readable ticks rather than magnified into a scribble of 12-digit labels (issue 60 item 19)
  const phase = refFm.curve.phase_deg;
  const spread = Math.max(...phase) - Math.min(...phase);
  const fmPhase = await page.evaluate(() => {
    const L = document.getElementById("afm-plot-b")._fullLayout;
    return { range: L.yaxis.range, ticks: (L.yaxis._vals ?? []).map((t) => t.text), title: L.title.text };
  });
  check("the FM phase (held at 90° by the PLL, spread only round-off) is drawn flat over ±0.1 %, its tick labels short and distinct",
    spread > 0 && spread <= 1e-6 * 90 && fmPhase.range[1] - fmPhase.range[0] >= 0.1 &&
    fmPhase.ticks.length >= 2 && new Set(fmPhase.ticks).size === fmPhase.ticks.length &&
    fmPhase.ticks.every((t) => t.length <= 6) && fmPhase.title.includes("constant"),
  `spread ${spread}; ${JSON.stringify(fmPhase)}`);
  await page.screenshot({ path: path.join(out, "screenshot-fm.png"), fullPage: true });
  // the FM amplitude and the z_c range from their fields, against the command line's
  await page.fill("#fm-amplitude", "12e-9");
  await page.fill("#curve-from", "30e-9");
  await page.fill("#curve-to", "14e-9");
  await page.fill("#points", "8");
  const fmA = await afmRun();
  const refFmA = native(["fm", "--probe", "examples/probe-point-mass-dmt.toml", "--amplitude", "12e-9",
    "--from", "30e-9", "--to", "14e-9", "--points", "8", "--out", tmp]);
  [w, where] = worst(fmA.curve, refFmA.curve);
  check("the FM amplitude and z_c range fields are the request's amplitude, from, to: " +
    "`afmdyn fm --amplitude 12e-9 --from 30e-9 --to 14e-9 --points 8 --json`'s curve (to 1e-8)",
  w <= 1e-8 && fmA.amplitude === 12e-9 && fmA.curve.z_c[0] === 30e-9 && fmA.curve.z_c.at(-1) === 14e-9,
  `${w} at ${where}; A = ${fmA.amplitude}; z_c ${fmA.curve.z_c[0]}…${fmA.curve.z_c.at(-1)}`);
  // a value the library refuses: its message beside the field (the page checks no range)
  await page.fill("#fm-amplitude", "-1");
  await page.click("#afm-run");
  await page.waitForFunction(() => document.getElementById("err-fm-amplitude").textContent !== "");
  const aMsg = await page.textContent("#err-fm-amplitude");
  const aCli = nativeError(["fm", "--probe", "examples/probe-point-mass-dmt.toml", "--amplitude", "-1", "--out", tmp]);
  check("a bad FM amplitude is refused beside its field with the library's message (the command line's)",
    aMsg === aCli && await page.getAttribute("#fm-amplitude", "aria-invalid") === "true", `"${aMsg}" vs "${aCli}"`);
  await page.fill("#fm-amplitude", "");
  await page.fill("#curve-from", "-3");
  await page.selectOption("#afm-analysis", "approach");
  await page.click("#afm-run");
  await page.waitForFunction(() => document.getElementById("err-curve-from").textContent !== "");
  const fMsg = await page.textContent("#err-curve-from");
  const fCli = nativeError(["approach", "--probe", "examples/probe-point-mass-dmt.toml", "--from", "-3", "--to", "14e-9", "--out", tmp]);
  check("a bad z_c start is refused beside its field with the library's message (the command line's)",
    fMsg === fCli, `"${fMsg}" vs "${fCli}"`);
  await page.fill("#curve-from", "");
  await page.fill("#curve-to", "");

  // bimodal: the two-mode probe preset against `afmdyn bimodal --json`
  await page.selectOption("#probe-preset", "probe-bimodal.toml");
  await page.selectOption("#afm-analysis", "bimodal");
  await page.fill("#points", "16");
  const bimodal = await afmRun();
  const refBimodal = native(["bimodal", "--probe", "examples/probe-bimodal.toml", "--points", "16", "--out", tmp]);
  [w, where] = worst(approachSweeps(bimodal), approachSweeps(refBimodal));
  const [wb, wbAt] = branchesScaled(bimodal.branches, refBimodal.branches);
  const [wf, wfAt] = worst({ ...approachBranches(bimodal), branches: null }, { ...approachBranches(refBimodal), branches: null });
  check("the bimodal curve of the preset probe-bimodal.toml is `afmdyn bimodal --json`'s " +
    "(sweeps to 1e-9; branches to 1e-6, 1e-4 at their grazing and fold events; folds to 1e-6); both modes drawn",
  w <= 1e-9 && wb <= 1 && wf <= 1e-6 &&
    await page.evaluate(() => document.getElementById("afm-plot-a").data.length === 4), `${w} at ${where}; ${wb} of the tolerance at ${wbAt}; ${wf} at ${wfAt}`);
  // A₂ on its own axis: mode 2's traces on the right axis, whose range holds A₂'s values
  const a2 = await page.evaluate(() => {
    const gd = document.getElementById("afm-plot-a");
    const L = gd._fullLayout;
    return { axes: gd.data.map((t) => t.yaxis ?? "y"), title: L.yaxis2?.title.text ?? "", range: L.yaxis2?.range ?? null };
  });
  const amp2 = [...refBimodal.approach.amplitude_2, ...refBimodal.retract.amplitude_2];
  check("bimodal: A₂ is drawn on its own (right) axis, A₁ on the left",
    JSON.stringify(a2.axes) === JSON.stringify(["y", "y", "y2", "y2"]) && a2.title.includes("A₂") && a2.range &&
    a2.range[0] <= Math.min(...amp2) && a2.range[1] >= Math.max(...amp2), JSON.stringify(a2));

  // PeakForce: a steady off-resonance tap of the preset probe-peakforce-air.toml against
  // `afmdyn peakforce --json`, each channel relative to its own size (the dissipation, ~0 for
  // this conservative DMT law, relative to the base's work per cycle)
  await page.selectOption("#probe-preset", "probe-peakforce-air.toml");
  await page.selectOption("#afm-analysis", "peakforce");
  const tap = await afmRun();
  const refTap = native(["peakforce", "--probe", "examples/probe-peakforce-air.toml", "--files", "none"]);
  const tapScale = (k) => (k === "dissipation" ? refTap.balance.modulation_work : Math.abs(refTap.channels[k]));
  const [wk, wv] = Object.keys(refTap.channels).map((k) => [k, Math.abs(tap.channels[k] - refTap.channels[k]) / tapScale(k)])
    .reduce((m, r) => (r[1] > m[1] || Number.isNaN(r[1]) ? r : m), ["", 0]);
  const tapShown = await page.evaluate(() => [document.getElementById("afm-plot-a").data.length,
    document.getElementById("afm-plot-b").data.length, document.getElementById("afm-summary").textContent]);
  check("the PeakForce tap of the preset probe-peakforce-air.toml is `afmdyn peakforce --json`'s " +
    "(channels to 1e-9 of their size); its force–distance curve, its cycle and its channels shown",
  wv <= 1e-9 && tapShown[0] === 2 && tapShown[1] === 2 && tapShown[2].includes("peak force") &&
    tapShown[2].includes("modulus_dmt"), `${wv} at ${wk}; ${tapShown[0]}, ${tapShown[1]} traces`);

  // an image: the stripe (one line) and the blend (a map) against `afmdyn image --json`
  await page.selectOption("#probe-preset", "probe-point-mass-dmt.toml");
  await page.selectOption("#afm-analysis", "image");
  await page.fill("#pixels", "16");
  for (const sample of ["sample-stripe.toml", "sample-blend.toml"]) {
    await page.selectOption("#sample-preset", sample);
    const image = await afmRun();
    const refImage = native(["image", "--probe", "examples/probe-point-mass-dmt.toml", "--sample", `examples/${sample}`,
      "--setpoint", "0.7", "--pixels", "16", "--out", tmp]);
    // the command line's document is a summary (its maps are image.nc's)
    [w, where] = imageAgainstSummary(image, refImage);
    const kind = await page.evaluate(() => document.getElementById("afm-plot-a").data[0].type);
    const listed = await page.$$eval("#afm-warnings li", (li) => li.map((x) => x.textContent));
    check(`… and its ${refImage.warnings.length} warning(s) are listed under the plots`,
      listed.length === refImage.warnings.length && refImage.warnings.every((m, i) => listed[i].includes(typeof m === "string" ? m : m.message ?? "")),
      JSON.stringify(listed));
    check(`the image of ${sample} is \`afmdyn image --setpoint 0.7 --pixels 16 --json\`'s (to 1e-9), drawn as ` +
      (refImage.image.lines === 1 ? "a line profile" : "maps"),
    w <= 1e-9 && kind === (refImage.image.lines === 1 ? "scatter" : "heatmap"), `${w} at ${where}; ${kind}`);
  }
  await page.screenshot({ path: path.join(out, "screenshot-image.png"), fullPage: true });
  // a PI-feedback image is the command line's only: the engine's refusal beside the field
  await page.selectOption("#feedback", "pi");
  await page.click("#afm-run");
  await page.waitForFunction(() => document.getElementById("err-feedback").textContent !== "");
  const piMsg = await page.textContent("#err-feedback");
  check("a PI-feedback image is refused beside its field: not in the browser, the command line's --feedback pi",
    piMsg.startsWith("feedback = pi: not in the browser") && piMsg.includes("afmdyn image --feedback pi"), piMsg);
  await page.selectOption("#feedback", "ideal");
  // a PeakForce image (ideal peak-force feedback) of the preset blend with the Amo & Garcia
  // probe against `afmdyn image --mode peakforce --json`'s summary, drawn as maps
  // (selects and fields of the form, set in order)
  const setForm = async (values) => {
    for (const [id, v] of values) {
      if ((await page.evaluate((i) => document.getElementById(i).tagName, id)) === "SELECT") await page.selectOption(`#${id}`, v);
      else await page.fill(`#${id}`, v);
    }
  };
  await setForm([["probe-preset", "probe-peakforce-amo-garcia.toml"], ["sample-preset", "sample-peakforce-blend.toml"],
    ["image-mode", "peakforce"], ["setpoint", "2e-9"], ["pixels", "6"], ["lines", "4"], ["afm-y", "modulus_dmt"]]);
  const pfImage = await afmRun();
  const refPf = native(["image", "--mode", "peakforce", "--probe", "examples/probe-peakforce-amo-garcia.toml",
    "--sample", "examples/sample-peakforce-blend.toml", "--setpoint", "2e-9", "--pixels", "6", "--lines", "4",
    "--files", "none"]);
  [w, where] = peakforceAgainstSummary(pfImage, refPf);
  const pfShown = await page.evaluate(() => [document.getElementById("afm-plot-a").data[0].type,
    document.getElementById("afm-plot-b").layout.title.text, document.getElementById("afm-summary").textContent,
    document.getElementById("setpoint-label").textContent]);
  check("the PeakForce image of the preset blend is `afmdyn image --mode peakforce --setpoint 2e-9 --pixels 6 " +
    "--lines 4 --json`'s (its summary, to 1e-6 relative), drawn as maps of height and modulus_dmt with each " +
    "material's operating point", w <= 1e-6 && pfShown[0] === "heatmap" && pfShown[1].startsWith("modulus") &&
    pfShown[2].includes("true E*") && pfShown[3].includes("peak force"), `${w} at ${where}; ${JSON.stringify(pfShown)}`);
  await setForm([["image-mode", "am"], ["setpoint", "0.7"], ["lines", ""], ["afm-y", "phase_deg"],
    ["probe-preset", "probe-point-mass-dmt.toml"], ["afm-analysis", "approach"]]);

  // a bad probe value: beside its field, the command line's message for that key
  await page.fill("#p-spring_constant", "-40");
  await page.dispatchEvent("#p-spring_constant", "change");
  await page.click("#afm-run");
  await page.waitForFunction(() => document.querySelector("#p-spring_constant + .error").textContent !== "");
  const kMsg = await page.textContent("#p-spring_constant + .error");
  check("a bad k is refused beside its field, naming [cantilever].spring_constant and the range",
    kMsg.startsWith("[cantilever].spring_constant = -40 (N/m): must be"), kMsg);
  // a key with no field of its own: its part of the message beside the probe file
  await page.fill("#p-spring_constant", "40");
  await page.dispatchEvent("#p-spring_constant", "change");
  await page.fill("#p-youngs_modulus", "-4e9");
  await page.dispatchEvent("#p-youngs_modulus", "change");
  await page.click("details:has(#probe-text) > summary");
  const text = await page.inputValue("#probe-text");
  await page.fill("#probe-text", text.replace(/poisson_ratio = 0\.33/, "poisson_ratio = 0.7"));
  await page.dispatchEvent("#probe-text", "change");
  await page.click("#afm-run");
  await page.waitForFunction(() => document.getElementById("err-probe").textContent !== "");
  const eMsg = await page.textContent("#p-youngs_modulus + .error");
  const rest = await page.textContent("#err-probe");
  check("every part of a probe's message is shown: E beside its field, the Poisson ratio (no field) beside the file",
    eMsg.startsWith("[sample].youngs_modulus = -4000000000") && rest.startsWith("probe: ") && rest.includes("[sample].poisson_ratio"),
    `${eMsg} | ${rest}`);

  // ------------------------------------------------------------------ the URL holds the view
  const shared = page.url();
  check("the URL holds the parameters", shared.includes("ws=afm") && shared.includes("spring_constant") && shared.includes("setpoint=0.7"));
  // the probe's own modes: in water the wet f₀ and Q (Sader's), the command line's
  await page.selectOption("#probe-preset", "probe-water-beam.toml");
  const water = readFileSync(path.join(root, "examples/probe-water-beam.toml"), "utf8");
  await page.waitForFunction((t) => window.explorer.probeModes?.text === t, water);
  const wet = await page.evaluate(() => ({ si: window.explorer.probeModes.si, text: document.getElementById("probe-modes").textContent }));
  const refWet = native(["modes", "--probe", "examples/probe-water-beam.toml"]).si.medium;
  check("the probe in water shows its wet f₀ and Q (`afmdyn modes --probe … --json`'s si.medium), not the file's",
    wet.si.medium.resonance_frequency === refWet.resonance_frequency && wet.si.medium.quality_factor === refWet.quality_factor &&
    wet.text.includes(`f₀ = ${refWet.resonance_frequency.toPrecision(6)} Hz`) && wet.text.includes(`Q = ${refWet.quality_factor.toPrecision(6)}`),
  `${wet.text} vs ${refWet.resonance_frequency}, ${refWet.quality_factor}`);
  // the example menu follows the text: an edit leaves no example named, and choosing the
  // example again restores its text
  await page.fill("#p-quality_factor", "300");
  await page.dispatchEvent("#p-quality_factor", "change");
  const edited = await page.inputValue("#probe-preset");
  await page.selectOption("#probe-preset", "probe-water-beam.toml");
  check("the example menu names no example once the probe is edited, and choosing it again restores its text",
    edited === "" && await page.inputValue("#probe-text") === water, `menu after the edit: "${edited}"`);

  const page2 = await context.newPage();
  await page2.goto(`${url}#ws=dyn&modes=2&alpha1=0.2&from=2.5&to=3&steps=12&omega=2.7`);
  await page2.waitForFunction(() => window.explorer?.timings.diagram_ms !== undefined);
  const restored = await page2.evaluate(() => ({
    modes: document.getElementById("modes").value, a1: document.getElementById("alpha1").value,
    rows: window.explorer.rows.length, om: document.getElementById("orbit-omega").value,
  }));
  const tmp2 = scratchDir();
  execFileSync(bin, ["bifurcation", "--modes", "2", "--tip-mass-ratio", "0.2", "--from", "2.5", "--to", "3", "--steps", "12", "--out", tmp2], { cwd: root });
  const cmp2 = compareBifurcation(await page2.evaluate(() => window.explorer.rows), readFileSync(path.join(tmp2, "bifurcation.csv"), "utf8"));
  check("a shared link restores the view and recomputes it (N = 2, α1 = 0.2: the command line's diagram)",
    restored.modes === "2" && restored.a1 === "0.2" && restored.om === "2.7" && !cmp2.bad && cmp2.far <= 1e-6,
    JSON.stringify(restored) + cmp2.bad);

  // a new request cancels the old: a 40-value diagram started and held back by the engine's
  // gate (its result is not delivered: it is certainly still running), then the 12-value one;
  // only the second's rows are shown (the command line's diagram)
  await page2.evaluate(() => window.explorer.hold(true));
  await page2.fill("#steps", "40");
  await page2.click("#dyn-run");
  await page2.waitForFunction(() => window.explorer.rows.length > 0);
  await page2.fill("#steps", "12");
  const [t12, running] = await page2.evaluate(() => [window.explorer.timings.diagram_ms, window.explorer.busy.diagram]);
  // the click cancels the held request at once (Engine.request); then the gate opens for
  // the new one
  await page2.click("#dyn-run");
  await page2.evaluate(() => window.explorer.hold(false));
  await page2.waitForFunction((t) => window.explorer.timings.diagram_ms !== t && !window.explorer.busy.diagram, t12);
  const cmp3 = compareBifurcation(await page2.evaluate(() => window.explorer.rows), readFileSync(path.join(tmp2, "bifurcation.csv"), "utf8"));
  check("a new diagram cancels the one running: only its rows are shown (the command line's)",
    running && !cmp3.bad && cmp3.far <= 1e-6, `${running ? "" : "the first had finished; "}${cmp3.bad}`);

  check("no error in the page's console", errors.length === 0, errors.join(" | "));
} catch (e) {
  check("the browser session ran to its end", false, e.stack);
} finally {
  await browser.close();
  for (const d of scratch) rmSync(d, { recursive: true, force: true });
}

console.log(`timings in the browser: default Fig. 5 diagram ${(timings.diagram / 1000).toFixed(2)} s ` +
  `(goal 3 s; page load included ${(timings.load_and_diagram / 1000).toFixed(2)} s), click to orbit ` +
  `${timings.click_to_orbit?.toFixed(0)} ms (goal 100 ms; the engine's shooting ${timings.orbit_engine?.toFixed(0)} ms; with its time series ${timings.click_to_orbit_view?.toFixed(0)} ms), ` +
  `approach curve (60 z_c each way, branches) ${(timings.approach / 1000).toFixed(2)} s (goal 2 s)`);
writeFileSync(path.join(out, "timings.json"), JSON.stringify({ ...timings, chromium: browserVersion }, null, 1));
console.log(`explorer: ${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
