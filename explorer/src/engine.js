// The page's side of the engine: lanes of Web Workers (worker.js), each running one request at a
// time. A new request on a lane cancels the one still running there by terminating its worker
// (the library's loops cannot be interrupted from outside; a fresh worker instantiates the
// already compiled module in milliseconds). The WebAssembly module is compiled once and handed
// to every worker.

export class Cancelled extends Error {
  constructor() {
    super("cancelled by a newer request");
    this.name = "Cancelled";
  }
}

export class Engine {
  /** @param {WebAssembly.Module} module the compiled afmdyn-wasm module */
  constructor(module, workerUrl) {
    this.module = module;
    this.workerUrl = workerUrl;
    this.lanes = new Map();
    this.nextId = 1;
  }

  static async load(wasmUrl, workerUrl) {
    const resp = await fetch(wasmUrl);
    const module = await WebAssembly.compile(await resp.arrayBuffer());
    return new Engine(module, workerUrl);
  }

  lane(name) {
    let lane = this.lanes.get(name);
    if (!lane) {
      lane = { worker: null, pending: null };
      this.lanes.set(name, lane);
    }
    if (!lane.worker) {
      lane.worker = new Worker(this.workerUrl, { type: "module" });
      lane.worker.postMessage({ kind: "init", module: this.module });
    }
    return lane;
  }

  cancel(name) {
    const lane = this.lanes.get(name);
    if (lane && lane.pending) {
      // no message of the old request may arrive after this (one already queued included)
      lane.worker.onmessage = null;
      lane.worker.onerror = null;
      lane.worker.terminate();
      lane.worker = null;
      const p = lane.pending;
      lane.pending = null;
      p.reject(new Cancelled());
    }
  }

  /**
   * Testing: while `on`, every request's last message (its result) is held back, so that the
   * request is certainly still running when a test starts a newer one (a gate, not a race);
   * `hold(false)` delivers the held results.
   */
  hold(on) {
    this.holding = on;
    if (on) return;
    for (const lane of this.lanes.values()) {
      const p = lane.pending;
      if (p?.held) {
        lane.pending = null;
        p.deliver(p.held);
      }
    }
  }

  /** End the lane's worker (cancelling its request, if any). */
  close(name) {
    this.cancel(name);
    const lane = this.lanes.get(name);
    if (lane?.worker) lane.worker.terminate();
    this.lanes.delete(name);
  }

  request(name, msg, onChunk) {
    this.cancel(name);
    const lane = this.lane(name);
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      const deliver = (m) => (m.ok ? resolve(m) : reject(new Error(m.error)));
      lane.pending = { id, reject, deliver, held: null };
      lane.worker.onmessage = (ev) => {
        const m = ev.data;
        if (m.id !== id) return;
        if (m.rows !== undefined) {
          onChunk?.(JSON.parse(m.rows), m.total);
          return;
        }
        if (this.holding) {
          lane.pending.held = m;
          return;
        }
        lane.pending = null;
        deliver(m);
      };
      lane.worker.onerror = (ev) => {
        lane.pending = null;
        reject(new Error(ev.message || "the engine's worker failed"));
      };
      lane.worker.postMessage({ id, ...msg });
    });
  }

  /** One analysis (crates/afmdyn-wasm `run`): the parsed document and the engine's time. */
  async run(lane, analysis, input) {
    const m = await this.request(lane, { kind: "run", analysis, input: JSON.stringify(input) });
    return { doc: JSON.parse(m.text), ms: m.ms };
  }

  /** A bifurcation diagram in chunks: `onRows(rows, total)` per chunk. */
  async bifurcation(input, chunk, onRows) {
    const m = await this.request("diagram",
      { kind: "bifurcation", input: JSON.stringify(input), chunk }, onRows);
    return { ms: m.ms };
  }
}
