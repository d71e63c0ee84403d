// explorer_redraw.mjs — the explorer page's redraw rate while a slider is dragged, per thesis
// case, in headless Chromium (bench/explorer_redraw.sh; bench/README.md).
//
//   node explorer_redraw.mjs PAGE [FRAMES] [PARAMETER]
//
// For each case: three trajectories launched from clicks (they are redrawn with the portrait),
// then the PARAMETER's slider (default K, the loop gain: every thesis case has K = 1) moved once per animation frame for FRAMES frames
// (default 60); prints the frames per second the page achieved (real frames: layout and paint
// included) and the mean time per redraw of each part, and the time of a 60 s trajectory.
import path from "node:path";
import { findChromium, openBrowser, dragExpression, releaseExpression } from "../tests/explorer/devtools.mjs";

const [page, framesArg = "60", parameter = "K"] = process.argv.slice(2);
const frames = Number(framesArg);
const chromium = findChromium();
if (!chromium) { console.log("no Chromium installed (apt-get install chromium)"); process.exit(1); }
const b = await openBrowser(chromium);
try {
  await b.cdp("Page.navigate", { url: "file://" + path.resolve(page) });
  await b.waitFor("window.explorer && window.explorer.ready === true && window.explorer.portrait !== null");
  const f = (x) => (x === undefined ? "  -  " : x.toFixed(1).padStart(5));
  console.log(`case  frames/s   per redraw [ms]: model  portrait (cycle+orbit, dividing lines)  step+runs  drawing   (${frames} frames, slider ${parameter})`);
  for (const id of ["I", "II", "III", "IV", "V", "VI", "VII", "VIII"]) {
    await b.evaluate(`document.getElementById("case").value = "${id}"; document.getElementById("case").dispatchEvent(new Event("change"))`);
    await b.frame();
    const traj = await b.evaluate(`(() => { const e = window.explorer, R = e.loaded.parameters.theta_R, w = e.view.x1 - e.view.x0, h = e.view.y1 - e.view.y0;
      const ms = [];
      for (const [x, y] of [[0.25, 0.7], [0.6, 0.3], [0.8, 0.75]]) { e.launch({ theta_o: e.view.x0 + x * w, dtheta_o: e.view.y0 + y * h, flight: false }); ms.push(e.trajectories[e.trajectories.length - 1].ms); }
      return ms; })()`);
    await b.frame();
    const metric = async () => Object.fromEntries((await b.cdp("Performance.getMetrics")).metrics.map((m) => [m.name, m.value]));
    const v0 = await b.evaluate(`document.getElementById("s_${parameter}").value`);
    const m0 = await metric();
    const r = await b.evaluate(dragExpression(parameter, frames));
    const m1 = await metric(), per = (k) => (1000 * (m1[k] - m0[k])) / r.redraws;
    await b.evaluate(releaseExpression(parameter, v0));
    console.log(`${id.padEnd(5)} ${r.fps.toFixed(1).padStart(8)}  ${" ".repeat(17)}${f(r.load_ms)}  ${f(r.portrait_ms)} (${f(r.cycle_ms)}, ${f(r.trace_ms)})${" ".repeat(20)}${f(r.runs_ms).padStart(9)}  ${f(r.draw_ms).padStart(7)}` +
      `   (60 s trajectory: ${traj.map((x) => x.toFixed(2)).join(", ")} ms; per frame: script ${per("ScriptDuration").toFixed(1)} ms, ` +
      `style+layout ${(per("RecalcStyleDuration") + per("LayoutDuration")).toFixed(1)} ms, all tasks ${per("TaskDuration").toFixed(1)} ms)`);
  }
  if (b.pageErrors.length) console.log("page errors: " + b.pageErrors.join("; "));
} finally {
  b.close();
}
