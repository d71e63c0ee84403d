// explorer_redraw.mjs — the explorer page's redraw rate while a slider is dragged, per thesis
// case, in headless Chromium (bench/explorer_redraw.sh; bench/README.md).
//
//   node explorer_redraw.mjs PAGE [FRAMES] [PARAMETER] [BASELINE_PAGE]
//
// For each case: three trajectories launched from clicks (they are redrawn with the portrait),
// then the PARAMETER's slider (default K, the loop gain: every thesis case has K = 1) moved once
// per animation frame for FRAMES frames (default 60), over ±30 % of its value; prints the frames
// per second the page achieved (real frames: layout, paint and raster included) and where a
// redraw's time goes: the page's own timings (the core's model, limit cycle and dividing lines,
// the runs, the drawing) and Chromium's (script, style and layout, all tasks of the frame); and
// the time of a 60 s trajectory.  With BASELINE_PAGE (e.g. main's build/explorer/index.html) the
// same drag on it, case by case in the same run, and the ratio of the frame rates.
import path from "node:path";
import { findChromium, openBrowser, dragExpression, releaseExpression } from "../tests/explorer/devtools.mjs";

const [page, framesArg = "60", parameter = "K", baseline] = process.argv.slice(2);
const frames = Number(framesArg);
const chromium = findChromium();
if (!chromium) { console.log("no Chromium installed (apt-get install chromium)"); process.exit(1); }

/// The page open in its own browser, ready.
async function open(file) {
  const b = await openBrowser(chromium);
  await b.cdp("Page.navigate", { url: "file://" + path.resolve(file) });
  await b.waitFor("window.explorer && window.explorer.ready === true && window.explorer.portrait !== null");
  return b;
}

/// Case `id` on page `b`: three trajectories, then the drag; the frame rate and the timings.
async function measure(b, id) {
  await b.evaluate(`document.getElementById("case").value = "${id}"; document.getElementById("case").dispatchEvent(new Event("change"))`);
  await b.frame();
  const traj = await b.evaluate(`(() => { const e = window.explorer, w = e.view.x1 - e.view.x0, h = e.view.y1 - e.view.y0, ms = [];
    for (const [x, y] of [[0.25, 0.7], [0.6, 0.3], [0.8, 0.75]]) { e.launch({ theta_o: e.view.x0 + x * w, dtheta_o: e.view.y0 + y * h, flight: false }); ms.push(e.trajectories[e.trajectories.length - 1].ms); }
    return ms; })()`);
  await b.frame();
  const metric = async () => Object.fromEntries((await b.cdp("Performance.getMetrics")).metrics.map((m) => [m.name, m.value]));
  const v0 = await b.evaluate(`document.getElementById("s_${parameter}").value`);
  const m0 = await metric();
  const r = await b.evaluate(dragExpression(parameter, frames));
  const m1 = await metric(), per = (k) => (1000 * (m1[k] - m0[k])) / r.redraws;
  await b.evaluate(releaseExpression(parameter, v0));
  return { ...r, traj, script: per("ScriptDuration"), layout: per("RecalcStyleDuration") + per("LayoutDuration"), tasks: per("TaskDuration") };
}

const b = await open(page);
const base = baseline ? await open(baseline) : null;
try {
  const f = (x) => (x === undefined ? "  -  " : x.toFixed(1).padStart(5));
  console.log(`${frames} frames per case, the slider ${parameter} moved over ±30 %; times per redraw [ms]`);
  console.log(`case  frames/s${base ? "  baseline  ratio" : ""} | model  cycle  dividing  runs  drawing | script  style+layout  all tasks | 60 s trajectory [ms]`);
  for (const id of ["I", "II", "III", "IV", "V", "VI", "VII", "VIII"]) {
    const r = await measure(b, id), old = base ? await measure(base, id) : null;
    console.log(`${id.padEnd(5)} ${r.fps.toFixed(1).padStart(8)}` + (old ? `  ${old.fps.toFixed(1).padStart(8)}  ${(r.fps / old.fps).toFixed(2).padStart(5)}` : "") +
      ` | ${f(r.load_ms)}  ${f(r.cycle_ms)}  ${f(r.trace_ms).padStart(8)}  ${f(r.runs_ms).padStart(4)}  ${f(r.draw_ms).padStart(7)} | ` +
      `${f(r.script).padStart(6)}  ${f(r.layout).padStart(12)}  ${f(r.tasks).padStart(9)} | ${r.traj.map((x) => x.toFixed(2)).join(", ")}`);
  }
  for (const x of [b, base]) if (x && x.pageErrors.length) console.log("page errors: " + x.pageErrors.join("; "));
} finally {
  b.close();
  if (base) base.close();
}
