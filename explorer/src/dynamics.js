// The Dynamics workspace's fields as the engine's request: the model keys of a `--config` file
// (afmdyn::request::ModelSpec: modes, alpha1…alpha6, contact_law, omega) and the keywords of
// `afmdyn bifurcation` (from, to, steps; the sweep of Ω). Presets: the paper's figures
// (examples/fig5.toml, fig8-14.toml, fig15-17.toml, eq25.toml; docs/paper-reproduction.md).

/** The fields of the model and the sweep, by element id (= the request's key). */
export const DYN_FIELDS = ["modes", "alpha1", "alpha2", "alpha3", "alpha4", "alpha5", "alpha6",
  "contact_law", "from", "to", "steps"];

const EQ26 = { modes: 3, alpha1: 0.1, alpha2: 0.1, alpha3: 0.1, alpha4: 20, alpha5: 0, alpha6: 0.2, contact_law: "linear" };

export const DYN_PRESETS = [
  { id: "fig5", label: "Fig. 5: eq. 26, N = 3, Ω from 1 to 5 (400 values)",
    values: { ...EQ26, from: 1, to: 5, steps: 400 } },
  { id: "fig8-14", label: "Figs. 8–14: eq. 26 around Ω = 20 (α1 = 0.1)",
    values: { ...EQ26, from: 19, to: 21, steps: 100 } },
  { id: "fig15-17", label: "Figs. 15–17: α1 = 0 around Ω = 20",
    values: { ...EQ26, alpha1: 0, from: 19, to: 21, steps: 100 } },
  { id: "eq25", label: "Eq. 25: N = 5, undamped (natural frequencies only)", modesOnly: true,
    values: { ...EQ26, modes: 5, alpha3: 0, alpha6: 0 } },
];

/** The model keys of the fields' values (`v` by field id). */
export function dynModel(v) {
  const m = { modes: v.modes, contact_law: v.contact_law };
  for (let i = 1; i <= 6; i++) m[`alpha${i}`] = v[`alpha${i}`];
  if (v.omega !== undefined) m.omega = v.omega;
  for (const k of Object.keys(m)) if (m[k] === undefined) delete m[k];
  return m;
}

/** The bifurcation request of the fields' values: Ω from `from` to `to` in `steps` values. */
export function dynRequest(v) {
  const r = { param: "omega", from: v.from, to: v.to, steps: v.steps };
  for (const k of Object.keys(r)) if (r[k] === undefined) delete r[k];
  return r;
}
