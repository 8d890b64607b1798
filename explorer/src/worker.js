// The engine's Web Worker: the afmdyn library compiled to WebAssembly (crates/afmdyn-wasm) runs
// here, off the page's thread, so the page never freezes. One request at a time; the page cancels
// a request by terminating this worker and starting another (engine.js).
//
// Messages in:  {kind: "init", module}  (a compiled WebAssembly.Module, shared by every worker)
//               {id, kind: "run", analysis, input}      → {id, ok, text | error, ms}
//               {id, kind: "bifurcation", input, chunk} → {id, rows, total} per chunk, then
//                                                          {id, ok, done: true, ms}
import init, * as wasm from "afmdyn-wasm";

let ready = null;

function reply(msg) {
  self.postMessage(msg);
}

async function handle(msg) {
  await ready;
  const t0 = performance.now();
  try {
    if (msg.kind === "run") {
      // the engine's data besides its analyses: the cantilever library, bifurcation.csv's
      // columns, the contact laws' registry, the version
      const data = { cantilevers: wasm.cantilevers, bifurcation_columns: wasm.bifurcation_columns,
        laws: wasm.laws,
        version: () => JSON.stringify(wasm.version()) }[msg.analysis];
      // reconstruct_fm: the force behind an fm document (the input is that document)
      const text = data ? data() : msg.analysis === "reconstruct_fm" ? wasm.reconstruct_fm(msg.input)
        : wasm.run(msg.analysis, msg.input);
      reply({ id: msg.id, ok: true, text, ms: performance.now() - t0 });
    } else if (msg.kind === "bifurcation") {
      const b = new wasm.Bifurcation(msg.input);
      const total = b.total();
      try {
        while (!b.finished()) {
          const rows = b.next(msg.chunk);
          reply({ id: msg.id, rows, total });
        }
      } finally {
        b.free();
      }
      reply({ id: msg.id, ok: true, done: true, ms: performance.now() - t0 });
    }
  } catch (e) {
    reply({ id: msg.id, ok: false, error: e instanceof Error ? e.message : String(e) });
  }
}

let queue = Promise.resolve();
self.onmessage = (ev) => {
  const msg = ev.data;
  if (msg.kind === "init") {
    ready = init({ module_or_path: msg.module });
    return;
  }
  queue = queue.then(() => handle(msg));
};
