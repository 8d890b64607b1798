// Builds the explorer's static site: node explorer/build.mjs --pkg DIR --out DIR
//   --pkg: the wasm-bindgen output of crates/afmdyn-wasm (`--target web`: afmdyn_wasm.js and
//          afmdyn_wasm_bg.wasm; scripts/explorer.sh makes it)
//   --out: the site (index.html, style.css, main.js, worker.js, pkg/afmdyn_wasm_bg.wasm,
//          presets/: the repository's example probe files and sample maps, and their index)
// esbuild bundles the page (with Plotly's basic bundle and smol-toml from npm) and the worker
// (with the engine's glue); nothing is loaded from elsewhere at run time, so the site works from
// any static host.
import { build } from "esbuild";
import { copyFileSync, mkdirSync, readdirSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.resolve(here, "..");
const arg = (name) => {
  const i = process.argv.indexOf(name);
  if (i < 0 || !process.argv[i + 1]) throw new Error(`usage: node build.mjs --pkg DIR --out DIR (missing ${name})`);
  return path.resolve(process.argv[i + 1]);
};
const pkg = arg("--pkg");
const out = arg("--out");

rmSync(out, { recursive: true, force: true });
mkdirSync(path.join(out, "pkg"), { recursive: true });
mkdirSync(path.join(out, "presets"), { recursive: true });

await build({
  entryPoints: { main: path.join(here, "src/main.js"), worker: path.join(here, "src/worker.js") },
  bundle: true,
  format: "esm",
  target: "es2022",
  minify: true,
  sourcemap: true,
  outdir: out,
  alias: { "afmdyn-wasm": path.join(pkg, "afmdyn_wasm.js") },
  logLevel: "warning",
});
for (const f of ["index.html", "style.css"]) copyFileSync(path.join(here, f), path.join(out, f));
copyFileSync(path.join(pkg, "afmdyn_wasm_bg.wasm"), path.join(out, "pkg/afmdyn_wasm_bg.wasm"));

// the example probe files and sample maps as presets, titled by their first comment line
const examples = path.join(root, "examples");
const presets = readdirSync(examples).filter((f) => /^(probe|sample).*\.toml$/.test(f)).sort().map((file) => {
  const text = readFileSync(path.join(examples, file), "utf8");
  copyFileSync(path.join(examples, file), path.join(out, "presets", file));
  const first = text.split("\n").find((l) => l.startsWith("#")) ?? "";
  const kind = file.startsWith("probe") ? "probe" : "sample";
  return { file, kind, title: first.replace(/^#\s*/, "").replace(/\s*\(.*$/, "").slice(0, 90) };
});
writeFileSync(path.join(out, "presets/index.json"), JSON.stringify(presets, null, 1));
console.log(`explorer: built ${out} (${presets.length} probe presets)`);
