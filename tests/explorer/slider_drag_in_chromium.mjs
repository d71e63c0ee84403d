// explorer_slider_drag_in_chromium (issue 20, the redraw while a slider moves): a scripted drag of
// a slider through several values, one input event per animation frame as a user's drag delivers
// them, then the page's portrait at the final value against the CLI on the page's own case file
// (the "case file" download, S.loaded.case_file): the limit cycle (`limit-cycle FILE --json`: the
// status, the reason, every number to 1e-12 relative — the peak-to-peak among them), the dividing
// lines' points of θ̇m0 > 0 (`trace FILE --json`, to 1e-12) and the kept trajectory's events
// (`simulate FILE --from θo,θ̇o --t-end T --json`, to 1e-12).
//   - case II, FL from 0 through 2e-4 … 5.5e-4: a nearly frictionless load, where the cycle
//     survey's half cycles bounce and the flight after the bounce returns to its face (the
//     search that stops the opposite face's scan there: numeric/hybrid/first_crossing.cpp,
//     first_crossing_or_return), and the dividing lines' horizon is 40·JL/FL;
//   - case III, FL through 1e-3 … 0.02, where a limit cycle exists.
// It guards the correctness of the faster paths (no timing: bench/explorer_redraw.sh measures
// the rate).  The page computes each frame from scratch, so the answer at the final value must be
// the CLI's whatever values came before.
//
//   node slider_drag_in_chromium.mjs PAGE BACKLASH_CLI [built|not-built]
// Exit 77 (ctest SKIP_RETURN_CODE) with the reason when there is no Chromium or no page.
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { chromiumForTest, checks, compareDividingLines, openBrowser } from "./devtools.mjs";

const [page, cli, built = "built"] = process.argv.slice(2);
const chromium = chromiumForTest(page, built);
const { check, finish } = checks();
const close = (a, b) => Math.abs(a - b) <= 1e-12 * Math.max(1, Math.abs(b));
const folder = fs.mkdtempSync(path.join(os.tmpdir(), "explorer-drag-"));
const b = await openBrowser(chromium);
const watchdog = setTimeout(() => { console.log("FAIL: the drag test ran over 110 s"); b.close(); process.exit(1); }, 110000);

/// Case `id` with two trajectories launched, then the slider `name` moved through `values`, one
/// per frame, and released.  Returns what the page shows and its case file.
async function drag(id, name, values) {
  await b.evaluate(`document.getElementById("case").value = "${id}"; document.getElementById("case").dispatchEvent(new Event("change"))`);
  await b.frame();
  await b.evaluate(`(() => { const e = window.explorer, w = e.view.x1 - e.view.x0, h = e.view.y1 - e.view.y0;
    for (const [x, y] of [[0.25, 0.7], [0.7, 0.35]]) e.launch({ theta_o: e.view.x0 + x * w, dtheta_o: e.view.y0 + y * h, flight: false }); })()`);
  const redraws0 = await b.evaluate("window.explorer.redraws");
  for (const v of values) {
    await b.evaluate(`(() => { const s = document.getElementById("s_${name}"); s.value = ${v}; s.dispatchEvent(new Event("input")); })()`);
    await b.frame();
  }
  await b.evaluate(`document.getElementById("s_${name}").dispatchEvent(new Event("change"))`);
  await b.frame();
  return b.evaluate(`(() => { const e = window.explorer, t = e.trajectories[e.trajectories.length - 1];
    return { redraws: e.redraws - ${redraws0}, field: document.getElementById("f_${name}").value, bad: document.getElementById("status").className === "bad",
      status: document.getElementById("status").textContent, cycle: e.portrait.cycle, points: e.portrait.trace.points, caseFile: e.loaded.case_file,
      run: t && { start: t.start, t_end: t.t_end, events: t.simulation.events } }; })()`);
}

/// A value of the page equal to the CLI's: numbers to 1e-12 relative, arrays and objects member
/// by member at any depth (the page's WebAssembly libm may differ in a last bit), the rest exactly.
function sameValue(p, v) {
  if (typeof v === "number" && typeof p === "number") return close(p, v);
  if (Array.isArray(v)) return Array.isArray(p) && p.length === v.length && v.every((x, i) => sameValue(p[i], x));
  if (v !== null && typeof v === "object")
    return p !== null && typeof p === "object" && Object.keys(p).length === Object.keys(v).length &&
      Object.entries(v).every(([k, x]) => sameValue(p[k], x));
  return p === v;
}

/// Every key of the CLI's document equal in the page's (sameValue).
function sameDocument(page, cli, skip) {
  const differ = [];
  for (const [k, v] of Object.entries(cli)) {
    if (skip.includes(k)) continue;
    const p = page[k];
    if (!sameValue(p, v)) differ.push(`${k}: page ${JSON.stringify(p)}, CLI ${JSON.stringify(v)}`);
  }
  return differ;
}

async function scenario(id, name, values) {
  const label = `case ${id}, ${name} dragged through ${values.join(", ")}`;
  const r = await drag(id, name, values);
  check(`${label}: the page redrew every frame, no error shown`, r.redraws >= values.length && !r.bad && Number(r.field) === values[values.length - 1],
    `${r.redraws} redraws for ${values.length} values, field ${r.field}${r.bad ? ", status: " + r.status : ""}`);
  const file = path.join(folder, `${id}_${name}.toml`);
  fs.writeFileSync(file, r.caseFile);
  const backlash = (...args) => JSON.parse(execFileSync(cli, [args[0], file, ...args.slice(1), "--json"]).toString());
  const cycle = backlash("limit-cycle");
  const differ = sameDocument(r.cycle, cycle, ["case"]);
  check(`${label}: the limit cycle equals \`limit-cycle FILE --json\` at the final value (status, reason, numbers to 1e-12)`, differ.length === 0,
    `status ${r.cycle.status}, peak-to-peak page ${r.cycle.peak_to_peak}, CLI ${cycle.peak_to_peak}${differ.length ? "; " + differ.join("; ").slice(0, 400) : ""}`);
  const { count, same, worst } = compareDividingLines(r.points, backlash("trace").points);
  check(`${label}: the dividing lines (θ̇m0 > 0) equal \`trace FILE --json\` at the final value, to 1e-12`, same && worst <= 1e-12,
    `${count} points, statuses ${same ? "equal" : "differ"}, largest relative difference ${worst}`);
  const run = r.run, sim = backlash("simulate", "--from", `${run.start.theta_o},${run.start.dtheta_o}`, "--t-end", String(run.t_end));
  let worstEvent = 0, kinds = run.events.length === sim.events.length;
  for (let i = 0; kinds && i < sim.events.length; i++) {
    kinds = run.events[i].kind === sim.events[i].kind;
    for (const k of ["t", "theta_o", "dtheta_o", "theta_m", "theta_L"]) worstEvent = Math.max(worstEvent, Math.abs(run.events[i][k] - sim.events[i][k]));
  }
  check(`${label}: the kept trajectory's events equal \`simulate FILE --from θo,θ̇o --t-end T --json\`, to 1e-12`, kinds && worstEvent <= 1e-12,
    `${sim.events.length} events, kinds ${kinds ? "equal" : "differ"}, largest difference ${worstEvent}`);
}

try {
  await b.cdp("Page.navigate", { url: "file://" + path.resolve(page) });
  await b.waitFor("window.explorer && window.explorer.ready === true && window.explorer.portrait !== null");
  await scenario("II", "FL", [0.0002, 0.0009, 0.0004, 0.0007, 0.00055]);
  await scenario("III", "FL", [0.001, 0.03, 0.005, 0.02]);
  if (b.pageErrors.length) check("no script errors on the page", false, b.pageErrors.join("; "));
} catch (error) {
  check("the drag scenarios ran", false, error.stack.slice(0, 600));
} finally {
  clearTimeout(watchdog);
  b.close();
  fs.rmSync(folder, { recursive: true, force: true });
}
finish();
