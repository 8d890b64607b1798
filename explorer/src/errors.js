// Where an engine message goes: the library's one-line messages name the field first
// (`alpha1 (tip-mass ratio α1) = -1: must be finite and >= 0`, `setpoint = 2: must be in
// (0, 1]…`) or, for a probe file, name each key as `[section].key` (`probe: [cantilever].
// spring_constant = -40 (N/m): must be finite and > 0; missing key [sample].hamaker (J)`).

/** [[element, message]] for a message whose first word is a field `locate` knows. */
export function fieldErrors(message, locate) {
  const m = /^([a-z_][a-z0-9_]*)\b/.exec(message);
  const el = m ? locate(m[1]) : null;
  return el ? [[el, message]] : [];
}

/** [[element, part]] for each `; `-separated part of a probe message naming a key `locate`
 * knows (`[section].key` → "section.key"), the other parts together beside `rest`; nothing
 * when no part is placed. */
export function probeErrors(message, locate, rest) {
  const out = [];
  const left = [];
  for (const part of message.replace(/^probe[^:]*: /, "").split("; ")) {
    const m = /\[([a-z_]+)\]\.([a-z_0-9]+)/.exec(part);
    const el = m ? locate(`${m[1]}.${m[2]}`) : null;
    if (el) out.push([el, part]);
    else left.push(part);
  }
  if (out.length && left.length) out.push([rest, `probe: ${left.join("; ")}`]);
  return out;
}
