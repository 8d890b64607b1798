// The page's shared pieces: the element lookup, the colours and Plotly options of every plot,
// and a summary list (a <dl> of label–value pairs).

/** The element of id `id`. */
export const $ = (id) => document.getElementById(id);
/** The colours of a sweep's two directions and of a selected point. */
export const COLOURS = { forward: "#1f5fbf", backward: "#c0392b", selected: "#f39c12" };
/** Plotly's options for every plot. */
export const PLOT_CONFIG = { responsive: true, displaylogo: false };

/** The entries `[label, value]` as the <dl> `el`'s terms and descriptions. */
export function summary(el, entries) {
  el.replaceChildren();
  for (const [k, v] of entries) {
    const dt = document.createElement("dt");
    dt.textContent = k;
    const dd = document.createElement("dd");
    dd.textContent = v;
    el.append(dt, dd);
  }
}
