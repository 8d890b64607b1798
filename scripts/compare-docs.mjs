// Comparing the engine's documents with the native command line's, shared by the WebAssembly
// check under Node.js (scripts/wasm-check.mjs) and the explorer's browser test
// (explorer/tests/browser.mjs).
import { isDeepStrictEqual } from "node:util";

/** The largest difference of two documents' numbers relative to 1 + |native|, and where
 * (Infinity where their shapes, keys, strings or flags differ): wasm's libm (sin, exp, pow) is
 * not the platform's, so their last bits may differ. */
export function worst(a, b, at = "") {
  if (typeof a === "number" && typeof b === "number") {
    if (Number.isNaN(a) && Number.isNaN(b)) return [0, at];
    return [Math.abs(a - b) / (1 + Math.abs(b)), at];
  }
  if (Array.isArray(a) && Array.isArray(b) && a.length === b.length) {
    return a.reduce((m, x, i) => { const w = worst(x, b[i], `${at}[${i}]`); return w[0] > m[0] ? w : m; }, [0, at]);
  }
  if (a && b && typeof a === "object" && typeof b === "object" && !Array.isArray(a) && !Array.isArray(b)) {
    const ka = Object.keys(a).sort(), kb = Object.keys(b).sort();
    if (!isDeepStrictEqual(ka, kb)) return [Infinity, `${at} keys`];
    return ka.reduce((m, k) => { const w = worst(a[k], b[k], `${at}.${k}`); return w[0] > m[0] ? w : m; }, [0, at]);
  }
  return [isDeepStrictEqual(a, b) ? 0 : Infinity, at];
}

/** An image's document with every pixel (the browser's) against the command line's summary
 * (`afmdyn image --json`: the maps are image.nc's): the shared keys, and each map's count of
 * finite pixels, min, max and mean computed here from the pixels against the summary's; the
 * largest difference and where. */
export function imageAgainstSummary(doc, summary) {
  const keys = ["feedback", "setpoint", "reference_z_c", "materials", "warnings", "setpoint_study"]
    .filter((k) => k in doc || k in summary);
  let best = worst(Object.fromEntries(keys.map((k) => [k, doc[k]])),
    Object.fromEntries(keys.map((k) => [k, summary[k]])));
  for (const name of ["height", "z_c", "phase_deg", "true_height"]) {
    const v = doc.image[name].flat().filter((x) => typeof x === "number" && Number.isFinite(x));
    const m = summary.image.maps[name];
    const mine = [v.length, Math.min(...v), Math.max(...v), v.reduce((a, b) => a + b, 0) / v.length];
    const w = worst(mine, [m.finite, m.min, m.max, m.mean], `.image.maps.${name}`);
    if (w[0] > best[0]) best = w;
  }
  return best;
}

/** An approach curve's parts: the two sweeps and the setpoint's operating points (compared to
 * 1e-9), and the continued branches, folds and jumps, whose adaptive arclength steps carry
 * last-bit differences into the points they land on (compared to 1e-6). */
export const approachSweeps = (d) => ({ ...d, branches: null, folds: null, bistable: null, jumps: null });
export const approachBranches = (d) => ({ branches: d.branches, folds: d.folds, bistable: d.bistable, jumps: d.jumps });

/** The continued branches of two curves (approach, bimodal), each difference (relative to
 * 1 + |native|) divided by its tolerance: 1e-6, and 1e-4 at a point where the branch has an
 * event (grazing, fold), which the continuation locates to its own tolerance: z_c there may
 * differ by 1e-8 relative, and the contact fraction, which grows as the square root of the
 * penetration past grazing, by 1e-5. Returns [the largest ratio (≤ 1 passes), where]. */
export function branchesScaled(a, b) {
  if (a.length !== b.length) return [Infinity, `${a.length} branches, ${b.length} native`];
  let best = [0, ""];
  a.forEach((br, k) => {
    const ref = b[k];
    for (const key of Object.keys(ref)) {
      if (!Array.isArray(ref[key]) || !Array.isArray(br[key]) || br[key].length !== ref[key].length) {
        best = [Infinity, `.branches[${k}].${key}`];
        return;
      }
      ref[key].forEach((v, i) => {
        const tol = ref.event?.[i] ? 1e-4 : 1e-6;
        const [w, at] = worst(br[key][i], v, `.branches[${k}].${key}[${i}]`);
        if (w / tol > best[0]) best = [w / tol, at];
      });
    }
  });
  return best;
}

/** Bifurcation rows (the engine's, by name) against `afmdyn bifurcation`'s bifurcation.csv
 * text: the same rows (branch, status, point count, value); a periodic point's W(1, τ) values
 * to 1e-6, each point's cycle compared as a set (a steady state is reached when its returns
 * repeat to 1e-8, which wasm's last bits may reach a period earlier or later, so a period-n
 * cycle may start at another of its points); a nonperiodic motion's points are not comparable
 * one by one (last-bit differences grow at the Lyapunov rate).
 * Returns {bad: "" or the first differing row, far: the largest periodic difference,
 * rows, periodic: the number of periodic points}. */
export function compareBifurcation(engineRows, csvText) {
  const csv = csvText.trim().split("\n");
  const head = csv[0].split(",");
  const rows = [...engineRows].sort((a, b) => a.index - b.index ||
    (a.branch !== "forward") - (b.branch !== "forward") || a.point - b.point);
  let bad = rows.length === csv.length - 1 ? "" : `${rows.length} rows, ${csv.length - 1} in the file`;
  const groups = new Map();
  for (let i = 0; !bad && i < rows.length; i++) {
    const cells = csv[i + 1].split(",");
    const cell = (name) => cells[head.indexOf(name)];
    if (cell("branch") !== rows[i].branch || cell("status") !== rows[i].status ||
        cell("points") !== String(rows[i].points) || Number(cell("value")) !== rows[i].value) {
      bad = `row ${i}: ${cells.slice(0, 8).join(",")} against ${rows[i].branch},${rows[i].status},${rows[i].points}`;
    }
    if (rows[i].status !== "periodic") continue;
    const key = `${rows[i].index} ${rows[i].branch}`;
    const g = groups.get(key) || { file: [], wasm: [] };
    g.file.push(Number(cell("w_tip")));
    g.wasm.push(rows[i].w_tip);
    groups.set(key, g);
  }
  let far = 0;
  let farAt = "";
  for (const [key, g] of groups) {
    g.file.sort((a, b) => a - b);
    g.wasm.sort((a, b) => a - b);
    g.file.forEach((v, k) => {
      const d = Math.abs(v - g.wasm[k]) / (1 + Math.abs(v));
      if (d > far) { far = d; farAt = key; }
    });
  }
  return { bad, far, farAt, rows: rows.length, periodic: groups.size };
}

/** A PeakForce image's document with every pixel (the browser's) against the command line's
 * summary (`afmdyn image --mode peakforce --json`): mode, feedback, setpoint, taps and
 * warnings equal; the materials' engaged operating points and z_c,ref, and each map's count
 * of finite pixels, min, max and mean computed here from the pixels against the summary's,
 * relative to the native value (the maps are in SI: forces of nN) — the dissipation relative
 * to the peak force's work (setpoint × the largest deformation): a conservative law's is
 * round-off (1e-30 J), whose last bits wasm's libm changes; the largest relative difference
 * and where. */
export function peakforceAgainstSummary(doc, summary) {
  for (const k of ["mode", "feedback", "setpoint", "taps", "warnings"]) {
    if (!isDeepStrictEqual(doc[k], summary[k])) return [Infinity, `.${k}`];
  }
  const rel = (a, b, at) => {
    if (a === null && b === null) return [0, at];
    if (typeof a !== "number" || typeof b !== "number") return [Infinity, at];
    return [a === b ? 0 : Math.abs(a - b) / Math.max(Math.abs(b), 1e-300), at];
  };
  const work = summary.setpoint * summary.image.maps.deformation.max;
  let best = rel(doc.reference_z_c, summary.reference_z_c, ".reference_z_c");
  const more = (w) => { if (w[0] > best[0]) best = w; };
  if (doc.materials.length !== summary.materials.length) return [Infinity, ".materials"];
  doc.materials.forEach((m, k) => {
    const s = summary.materials[k];
    if (m.name !== s.name || m.evaluations !== s.evaluations) more([Infinity, `.materials[${k}]`]);
    for (const [key, v] of Object.entries(s.engaged ?? {})) {
      const at = `.materials[${k}].engaged.${key}`;
      more(key === "dissipation" ? [Math.abs(m.engaged[key] - v) / work, at]
        : typeof v === "number" ? rel(m.engaged[key], v, at)
        : [isDeepStrictEqual(m.engaged[key], v) ? 0 : Infinity, at]);
    }
  });
  for (const name of ["height", "modulus_dmt", "adhesion", "deformation", "dissipation", "peak_force"]) {
    const v = doc.image[name].flat().filter((x) => typeof x === "number" && Number.isFinite(x));
    const m = summary.image.maps[name];
    if (v.length !== m.finite) more([Infinity, `.image.maps.${name}.finite`]);
    const mine = [Math.min(...v), Math.max(...v), v.reduce((a, b) => a + b, 0) / v.length];
    [m.min, m.max, m.mean].forEach((x, i) => {
      // (a map whose values cancel, the apparent height's 0 on the background: absolute to
      // its largest value)
      const scale = name === "dissipation" ? work : Math.max(Math.abs(m.min), Math.abs(m.max));
      more([Math.abs(mine[i] - x) / scale, `.image.maps.${name}[${["min", "max", "mean"][i]}]`]);
    });
  }
  return best;
}
