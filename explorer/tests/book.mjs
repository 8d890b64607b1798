// The book in a real browser (issue 80; run by scripts/test-explorer.sh after browser.mjs, in the
// same headless Debian Chromium driven by playwright-core): the built book (scripts/build-book.sh)
// served on 127.0.0.1; its index page and its getting-started page open with their title and
// heading, every resource they load answers (no 404: the theme's CSS and scripts, the figures),
// and nothing is written to the console as an error.
//   node explorer/tests/book.mjs --url URL --chromium PATH
// Prints each check and "book: N passed, M failed" last.
import { chromium } from "playwright-core";

const arg = (name) => {
  const i = process.argv.indexOf(name);
  if (i < 0) throw new Error(`missing ${name}`);
  return process.argv[i + 1];
};
const url = arg("--url").replace(/\/?$/, "/");
let passed = 0, failed = 0;
function check(name, ok, detail = "") {
  if (ok) { passed += 1; console.log(`ok   ${name}`); }
  else { failed += 1; console.log(`FAIL ${name} ${detail}`); }
}

const browser = await chromium.launch({
  executablePath: arg("--chromium"),
  headless: true,
  args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
try {
  const page = await browser.newPage();
  page.setDefaultTimeout(30_000);
  // the browser's own request for /favicon.ico (the book declares no icon) is not the book's
  await page.route("**/favicon.ico", (route) => route.fulfill({ status: 204, body: "" }));
  const errors = [];
  page.on("pageerror", (e) => errors.push(`page error: ${e.message}`));
  page.on("console", (m) => { if (m.type() === "error") errors.push(`console: ${m.text()}`); });
  page.on("requestfailed", (r) => errors.push(`request failed: ${r.url()} ${r.failure()?.errorText}`));
  page.on("response", (r) => { if (r.status() >= 400) errors.push(`HTTP ${r.status()}: ${r.url()}`); });

  for (const [file, heading] of [["index.html", "afmdyn"], ["getting-started.html", "Getting started"]]) {
    errors.length = 0;
    const response = await page.goto(url + file, { waitUntil: "load" });
    check(`the book's ${file} loads`, response?.ok(), `status ${response?.status()}`);
    const title = await page.title();
    check(`${file}: the title names the page and the book`, title.includes(heading) && title.includes("afmdyn"),
      JSON.stringify(title));
    const h1 = (await page.textContent("h1"))?.replace(/[¶#\s]+$/u, "").trim();
    check(`${file}: its heading is "${heading}"`, h1 === heading, JSON.stringify(h1));
    check(`${file}: the theme's stylesheet applies`,
      await page.evaluate(() => [...document.styleSheets].some((s) => { try { return s.cssRules.length > 0; } catch { return false; } })));
    check(`${file}: no error in the console, no failed request`, errors.length === 0, errors.join(" | "));
  }
  // the root toctree links the getting-started page
  await page.goto(url + "index.html");
  check("the index links the getting-started page",
    await page.locator('a[href="getting-started.html"]').count() > 0);
} catch (e) {
  check("the book's pages open", false, String(e?.stack ?? e));
} finally {
  await browser.close();
}
console.log(`book: ${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
