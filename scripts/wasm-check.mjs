// The wasm engine (crates/afmdyn-wasm, built by scripts/test-wasm.sh) against the native command
// line: node scripts/wasm-check.mjs PKG.js AFMDYN_BIN. Each check compares the wasm document
// with `afmdyn … --json` (the same keys, words and flags; every number within 1e-9 of
// 1 + |native|: wasm's libm is not the platform's) or the error message;
// prints each result, the wasm and native wall times of the approach curve, and
// "wasm: N passed, M failed" last.
import { createRequire } from "node:module";
import { execFileSync } from "node:child_process";
import { readFileSync, writeFileSync } from "node:fs";
import { isDeepStrictEqual } from "node:util";
import path from "node:path";
import { worst, approachSweeps, approachBranches, compareBifurcation, imageAgainstSummary,
  peakforceAgainstSummary } from "./compare-docs.mjs";

const require = createRequire(import.meta.url);
const [pkg, bin] = process.argv.slice(2);
const wasm = require(path.resolve(pkg));
const root = path.resolve(path.dirname(new URL(import.meta.url).pathname), "..");
let passed = 0, failed = 0, message = "";

function native(args) {
  return JSON.parse(execFileSync(bin, [...args, "--json"], { cwd: root, encoding: "utf8" }));
}

function check(name, ok, detail = "") {
  if (ok) { passed += 1; console.log(`ok   ${name}`); }
  else { failed += 1; console.log(`FAIL ${name} ${detail}`); }
}

const orbitText = wasm.run("orbit", JSON.stringify({ model: { omega: 2.8 } }));
const orbit = JSON.parse(orbitText);
let [w, at] = worst(orbit, native(["orbit", "--omega", "2.8"]));
check("orbit Ω = 2.8 is `afmdyn orbit --omega 2.8 --json` (numbers to 1e-9)", w <= 1e-9,
  `${w} at ${at}`);
console.log(`     largest difference ${w.toExponential(1)} at ${at}`);

const probe = "examples/probe-point-mass-dmt.toml";
const text = readFileSync(path.join(root, probe), "utf8");
let t0 = performance.now();
const curve = JSON.parse(wasm.run("approach",
  JSON.stringify({ probe: text, request: { points: 60, setpoint: 0.7 } })));
const tWasm = (performance.now() - t0) / 1000;
t0 = performance.now();
const ref = native(["approach", "--probe", probe, "--points", "60", "--setpoint", "0.7"]);
const tNative = (performance.now() - t0) / 1000;
// the two sweeps and the setpoint's operating points to 1e-9; the continued branches, whose
// adaptive arclength steps carry last-bit differences into the points they land on, to 1e-6
[w, at] = worst(approachSweeps(curve), approachSweeps(ref));
check("approach from a probe: sweeps and setpoint are `afmdyn approach --probe … --json`'s " +
  "(numbers to 1e-9)", w <= 1e-9, `${w} at ${at}`);
console.log(`     largest difference ${w.toExponential(1)} at ${at}`);
[w, at] = worst(approachBranches(curve), approachBranches(ref));
check("approach from a probe: its branches, folds and jumps are the command line's (to 1e-6)",
  w <= 1e-6, `${w} at ${at}`);
console.log(`     largest difference ${w.toExponential(1)} at ${at}`);

// a bifurcation diagram in chunks of 5 points, as the page draws it, against bifurcation.csv
const tmp = execFileSync("mktemp", ["-d"], { encoding: "utf8" }).trim();
execFileSync(bin, ["bifurcation", "--from", "2.4", "--to", "3.2", "--steps", "12", "--out", tmp],
  { cwd: root });
const session = new wasm.Bifurcation(JSON.stringify({ request: { from: 2.4, to: 3.2, steps: 12 } }));
let rows = [];
while (!session.finished()) rows = rows.concat(JSON.parse(session.next(5)));
const { bad, far, periodic } = compareBifurcation(rows, readFileSync(path.join(tmp, "bifurcation.csv"), "utf8"));
check("a bifurcation in chunks of 5 is `afmdyn bifurcation`'s bifurcation.csv (rows; periodic " +
  "cycles to 1e-6)", !bad && far <= 1e-6, bad || `${far}`);
console.log(`     ${rows.length} rows, ${periodic} periodic points; their largest difference ` +
  `${far.toExponential(1)}`);

// simulate from the native period-2 orbit's state at Ω = 2.8 (the page's time series and phase
// portrait of a clicked orbit): the summary is `afmdyn simulate --json`'s, the series
// periods × samples_per_period + 1 samples, W(1,τ) and V_T those of its timeseries.npy
const z = native(["orbit", "--omega", "2.8"]).state;
const half = z.length / 2;
const simDir = execFileSync("mktemp", ["-d"], { encoding: "utf8" }).trim();
const simRef = native(["simulate", "--omega", "2.8", "--periods", "4", "--samples-per-period",
  "50", `--initial-modal=${z.slice(0, half).join(",")};${z.slice(half).join(",")}`,
  "--files", "data", "--out", simDir]);
const sim = JSON.parse(wasm.run("simulate", JSON.stringify({ model: { omega: 2.8 },
  request: { initial: z, periods: 4, samples_per_period: 50 } })));
// timeseries.npy: float64 rows after its header (magic, version 1, header length, dict)
const npy = readFileSync(path.join(simDir, "timeseries.npy"));
const body = 10 + npy.readUInt16LE(8);
const [rowsN, cols] = /'shape': \((\d+), (\d+)\)/.exec(npy.toString("latin1", 10, body)).slice(1).map(Number);
const column = (k) => Array.from({ length: rowsN }, (_, i) => npy.readDoubleLE(body + 8 * (i * cols + k)));
[w, at] = worst({ ...sim.summary, files: simRef.files }, simRef);
const [ws, ats] = worst([sim.series.v_t.values, sim.series.w_tip.values], [column(1), column(2)]);
const length = sim.series.tau.values.length;
check("simulate from the orbit's state: summary is `afmdyn simulate --json`'s (to 1e-9), " +
  "201 samples, W(1,τ) and V_T its timeseries.npy's (to 1e-9)",
  w <= 1e-9 && ws <= 1e-9 && length === 201 && rowsN === 201 && sim.summary.files === "none",
  `summary ${w} at ${at}, series ${ws} at ${ats}, ${length} samples`);
console.log(`     largest difference: summary ${w.toExponential(1)} at ${at}, series ` +
  `${ws.toExponential(1)} at ${ats}`);

const lib = JSON.parse(wasm.cantilevers());
check("cantilevers() is `afmdyn cantilevers --json`", isDeepStrictEqual(lib, native(["cantilevers"])));

// the ideal-feedback image of the stripe sample, as `afmdyn image … --json`
const sampleFile = "examples/sample-stripe.toml";
const sampleText = readFileSync(path.join(root, sampleFile), "utf8");
const imgDir = execFileSync("mktemp", ["-d"], { encoding: "utf8" }).trim();
const img = JSON.parse(wasm.run("image", JSON.stringify({ probe: text, sample: sampleText,
  request: { setpoint: 0.7, pixels: 16 } })));
// the command line's document is a summary (its maps are image.nc's): the pixels' statistics
[w, at] = imageAgainstSummary(img, native(["image", "--probe", probe, "--sample", sampleFile,
  "--setpoint", "0.7", "--pixels", "16", "--out", imgDir]));
check("image of the stripe sample is `afmdyn image --setpoint 0.7 --pixels 16 --json`'s " +
  "(its summary: numbers to 1e-9)", w <= 1e-9, `${w} at ${at}`);
console.log(`     largest difference ${w.toExponential(1)} at ${at}`);

// the PeakForce image of the blend (ideal peak-force feedback), as `afmdyn image --mode
// peakforce … --json`: its document with every pixel against the command line's summary
const pfImgProbe = "examples/probe-peakforce-amo-garcia.toml";
const pfImgSample = "examples/sample-peakforce-blend.toml";
const pfImg = JSON.parse(wasm.run("image", JSON.stringify({
  probe: readFileSync(path.join(root, pfImgProbe), "utf8"),
  sample: readFileSync(path.join(root, pfImgSample), "utf8"),
  request: { mode: "peakforce", setpoint: 2e-9, pixels: 6, lines: 4 } })));
[w, at] = peakforceAgainstSummary(pfImg, native(["image", "--mode", "peakforce", "--probe", pfImgProbe,
  "--sample", pfImgSample, "--setpoint", "2e-9", "--pixels", "6", "--lines", "4", "--files", "none"]));
check("PeakForce image of the blend is `afmdyn image --mode peakforce --setpoint 2e-9 --pixels 6 " +
  "--lines 4 --json`'s (its summary: numbers to 1e-6 relative)", w <= 1e-6 &&
  pfImg.image.modulus_dmt.length === 4 && pfImg.image.modulus_dmt[0].length === 6, `${w} at ${at}`);
console.log(`     largest difference ${w.toExponential(1)} at ${at}`);
message = "";
try {
  wasm.run("image", JSON.stringify({ probe: text, sample: sampleText,
    request: { mode: "peakforce", setpoint: 2e-9, pixels: 4 } }));
} catch (e) { message = String(e.message); }
check("a PeakForce image of an AM probe is refused, naming the off-resonance drive",
  message.includes("off-resonance"), message);

// wasm has no files: a height map file is refused with the library's message
message = "";
try {
  wasm.run("image", JSON.stringify({ probe: text, request: { setpoint: 0.7 },
    sample: 'size = [1.0e-6, 0.0]\nheight_map = "h.csv"\n' }));
} catch (e) { message = String(e.message); }
check("a height map file is refused in wasm, naming height_map",
  message.includes("height_map") && message.includes("h.csv") && !message.includes("\n"), message);

// the force behind an FM curve: wasm's fm document reconstructed in wasm and by
// `afmdyn reconstruct --fm` from the same document (force to 1e-9 of its extreme)
const fmDoc = wasm.run("fm", JSON.stringify({ probe: text, request: { points: 20 } }));
const fmFile = path.join(imgDir, "fm.json");
writeFileSync(fmFile, fmDoc);
const rec = JSON.parse(wasm.reconstruct_fm(fmDoc));
const refRec = native(["reconstruct", "--fm", fmFile, "--files", "none"]);
const scale = Math.max(...refRec.force.force.map(Math.abs));
const farF = Math.max(...rec.force.force.map((f, i) => Math.abs(f - refRec.force.force[i]) / scale));
[w, at] = worst({ ...rec, force: null, csv: null }, { ...refRec, force: null, csv: null });
check("reconstruct_fm of an fm document is `afmdyn reconstruct --fm` of it (force to 1e-9 of its " +
  "extreme; distances, law, the rest to 1e-9)", farF <= 1e-9 && w <= 1e-9 &&
  rec.force.force.length === 20 && worst(rec.force.distance, refRec.force.distance)[0] <= 1e-9 &&
  isDeepStrictEqual(rec.force.law, refRec.force.law), `${farF}; ${w} at ${at}`);
message = "";
try { wasm.reconstruct_fm(orbitText); } catch (e) { message = String(e.message); }
check("reconstruct_fm refuses a document that is no fm document, naming fm", message.startsWith("fm"), message);

// every analysis of the library's door is reached by its name: a force-curve fit (the curve as
// the request's columns) and a PeakForce tap against the command line's documents
const fitProbe = "examples/probe-fit-hertz.toml";
const fitCsv = readFileSync(path.join(root, "examples/force-curve-hertz.csv"), "utf8").trim().split("\n").slice(1)
  .map((l) => l.split(",").map(Number));
const fitWasm = JSON.parse(wasm.run("fit", JSON.stringify({ probe: readFileSync(path.join(root, fitProbe), "utf8"),
  request: { height: fitCsv.map((r) => r[0]), force: fitCsv.map((r) => r[1]) } })));
const fitRef = native(["fit", "--probe", fitProbe, "--data", "examples/force-curve-hertz.csv", "--files", "none"]);
[w, at] = worst(fitWasm.estimates, fitRef.estimates);
check("fit by name is `afmdyn fit --json`'s (estimates, errors, intervals and profiles to 1e-9)", w <= 1e-9, `${w} at ${at}`);
const pfProbe = "examples/probe-peakforce-air.toml";
const pfWasm = JSON.parse(wasm.run("peakforce", JSON.stringify({ probe: readFileSync(path.join(root, pfProbe), "utf8") })));
const pfRef = native(["peakforce", "--probe", pfProbe, "--files", "none"]);
// each channel against its own size (the dissipation of this conservative law against the
// base's work per cycle)
const pfScale = (k) => (k === "dissipation" ? pfRef.balance.modulation_work : Math.abs(pfRef.channels[k]));
const pfWorst = Math.max(...Object.keys(pfRef.channels).map((k) => Math.abs(pfWasm.channels[k] - pfRef.channels[k]) / pfScale(k)));
check("peakforce by name is `afmdyn peakforce --json`'s (channels to 1e-9 of their size)", pfWorst <= 1e-9, String(pfWorst));
message = "";
try { wasm.run("no-such-analysis", "{}"); } catch (e) { message = String(e.message); }
check("an unknown analysis is refused, listing the door's names", message.includes("peakforce") && message.includes("fit"), message);

message = "";
try { wasm.run("orbit", JSON.stringify({ model: { omega: -1 } })); }
catch (e) { message = String(e.message); }
check("a bad Ω is refused naming omega", message.includes("omega"), message);

console.log(`approach curve (60 z_c each way, branches): wasm ${tWasm.toFixed(2)} s, ` +
  `native ${tNative.toFixed(2)} s (whole command), ratio ${(tWasm / tNative).toFixed(2)}`);
console.log(`wasm: ${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
