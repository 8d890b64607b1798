// Exports of the current data: CSV (one row per record, the columns by name), JSON files and
// the plots as images.
import Plotly from "plotly.js-cartesian-dist-min";
import { peakforceRows } from "./peakforce.js";

function cell(v) {
  if (v === null || v === undefined) return "";
  const s = typeof v === "object" ? JSON.stringify(v) : String(v);
  return /[",\n]/.test(s) ? `"${s.replaceAll('"', '""')}"` : s;
}

/** CSV text of `rows` (objects with the same keys). */
export function toCsv(rows) {
  if (!rows.length) return "";
  const keys = Object.keys(rows[0]);
  return [keys.join(","), ...rows.map((r) => keys.map((k) => cell(r[k])).join(","))].join("\n") + "\n";
}

/** Offer `text` as a file download named `name`. */
export function download(name, text, type) {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const a = document.createElement("a");
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

/** Export what the page shows: `what` "dyn" (the diagram as bifurcation.csv, or the orbit as
 * JSON), "afm" (the AFM document as JSON, or its rows as CSV), else the plot of that id as an
 * image; `format` "csv", "json", "png" or "svg"; `state` the page's (main.js). */
export function exportData(state, format, what) {
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
