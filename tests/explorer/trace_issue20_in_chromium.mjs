// explorer_trace_issue20_in_chromium (issue 20, two slider drags the page refused with "the
// certified event search exhausted its budget of 2000000 intervals"):
//   item1: case I, the reference θR dragged through 0.7, 0.95, 0.99 (the dividing lines' search
//          in absolute coordinates could not pass θR's rounding);
//   item2: case IV, FL dragged to 1e-5 (horizon 40·JL/FL = 3.2e6 s: the search's budget, now a
//          status, and the grid decided from the span it certified).
// After each drag: no error shown, and the dividing lines (θ̇m0 > 0) equal `trace FILE --json` on
// the page's own case file (statuses exactly, numbers to 1e-12 relative, as the other drag test).
//
//   node trace_issue20_in_chromium.mjs PAGE BACKLASH_CLI [built|not-built]
// Exit 77 (ctest SKIP_RETURN_CODE) with the reason when there is no Chromium or no page.
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { chromiumForTest, checks, compareDividingLines, openBrowser } from "./devtools.mjs";

const [page, cli, built = "built"] = process.argv.slice(2);
const chromium = chromiumForTest(page, built);
const { check, finish } = checks();
const folder = fs.mkdtempSync(path.join(os.tmpdir(), "explorer-trace20-"));
const b = await openBrowser(chromium);
const watchdog = setTimeout(() => { console.log("FAIL: the test ran over 100 s"); b.close(); process.exit(1); }, 100000);

async function scenario(item, id, name, values) {
  const label = `${item}: case ${id}, ${name} dragged through ${values.join(", ")}`;
  await b.evaluate(`document.getElementById("case").value = "${id}"; document.getElementById("case").dispatchEvent(new Event("change"))`);
  await b.frame();
  for (const v of values) {
    await b.evaluate(`(() => { const s = document.getElementById("s_${name}"); s.value = ${v}; s.dispatchEvent(new Event("input")); })()`);
    await b.frame();
  }
  await b.evaluate(`document.getElementById("s_${name}").dispatchEvent(new Event("change"))`);
  await b.frame();
  const r = await b.evaluate(`(() => { const e = window.explorer;
    return { field: document.getElementById("f_${name}").value, bad: document.getElementById("status").className === "bad",
      status: document.getElementById("status").textContent, points: e.portrait.trace.points, caseFile: e.loaded.case_file }; })()`);
  check(`${label}: the page drew the frame, no error shown`, !r.bad && Number(r.field) === values[values.length - 1],
    `field ${r.field}${r.bad ? ", status: " + r.status : ""}`);
  const file = path.join(folder, `${id}_${name}.toml`);
  fs.writeFileSync(file, r.caseFile);
  const trace = JSON.parse(execFileSync(cli, ["trace", file, "--json"]).toString()).points;
  const c = compareDividingLines(r.points, trace, true), same = !r.bad && c.same;  // not the last valid frame's
  check(`${label}: the dividing lines (θ̇m0 > 0) equal \`trace FILE --json\`, every point decided, to 1e-12`, same && c.worst <= 1e-12,
    `${c.count} points, statuses ${same ? "equal" : "differ or undecided"}, largest relative difference ${c.worst}`);
}

try {
  await b.cdp("Page.navigate", { url: "file://" + path.resolve(page) });
  await b.waitFor("window.explorer && window.explorer.ready === true && window.explorer.portrait !== null");
  await scenario("item1", "I", "reference", [0.7, 0.95, 0.99]);
  await scenario("item2", "IV", "FL", [0.00001]);
  if (b.pageErrors.length) check("no script errors on the page", false, b.pageErrors.join("; "));
} catch (error) {
  check("the scenarios ran", false, error.stack.slice(0, 600));
} finally {
  clearTimeout(watchdog);
  b.close();
  fs.rmSync(folder, { recursive: true, force: true });
}
finish();
