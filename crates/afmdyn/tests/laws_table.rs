//! The table of registered contact laws in docs/contact-laws.md (between its `laws-table`
//! markers) is generated from the registry ([`afmdyn::contact::LAWS`]: name, aliases, doc line,
//! dimensionless groups with symbol, unit, range and default, the probe's `[sample]` keys) and
//! must equal the committed text, so that the docs cannot drift from the code.
//! `AFMDYN_WRITE_SCHEMA=1 cargo test -p afmdyn --lib integration::laws_table::` rewrites it.

#![cfg(not(feature = "toy-law"))]

use afmdyn::contact::LAWS;

const BEGIN: &str = "<!-- laws-table: generated from afmdyn::contact::LAWS by crates/afmdyn/tests/laws_table.rs; do not edit -->";
const END: &str = "<!-- end of laws-table -->";

/// The generated table (Markdown), one row per registered law in registry order.
fn table() -> String {
    let mut t = String::from(
        "| law | what it is | its own groups: symbol (unit) range, default | probe `[sample]` keys |\n|---|---|---|---|\n",
    );
    for l in LAWS {
        let name = match l.aliases {
            [] => format!("`{}`", l.name),
            a => format!(
                "`{}` (also {})",
                l.name,
                a.iter()
                    .map(|a| format!("`{a}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
        let groups = match l.params {
            [] => "— (α4, α6 only)".to_string(),
            ps => ps
                .iter()
                .map(|p| {
                    format!(
                        "`{}` {} ({}) {}, default {}",
                        p.name, p.symbol, p.unit, p.range, p.default
                    )
                })
                .collect::<Vec<_>>()
                .join("; "),
        };
        let keys = l
            .sample_keys
            .iter()
            .map(|k| format!("`{k}`"))
            .collect::<Vec<_>>()
            .join(", ");
        t.push_str(&format!(
            "| {name} | {} | {groups} | {keys} |\n",
            l.doc.replace('|', "\\|")
        ));
    }
    t
}

#[test]
fn the_docs_table_of_laws_is_the_registry() {
    super::common::generated_section("docs/contact-laws.md", BEGIN, END, &table(), "laws_table");
}
