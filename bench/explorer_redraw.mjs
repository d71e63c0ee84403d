// explorer_redraw.mjs — the explorer page's redraw rate while a slider is dragged, per thesis
// case, in headless Chromium (bench/explorer_redraw.sh; bench/README.md).
//
//   node explorer_redraw.mjs PAGE [FRAMES] [PARAMETER] [BASELINE_PAGE]
//
// PARAMETER: a slider of the page by its field's name (Jm, Fm, JL, FL, K, backlash, reference,
// step, t_end, or an effect's parameter: coulomb_motor, restitution, …; the aliases b, θR and
// thetaR name backlash and reference), several separated by commas, or `all`: every slider the
// page has, read from the page itself (`parameters`: its parameter fields' alone, `effects`: its
// effects' alone).  Default K.
//
// For each case: three trajectories launched from clicks (they are redrawn with the portrait),
// then the slider moved once per animation frame for FRAMES frames (default 60), over ±30 % of
// its value (a value 0 — FL in cases II–IV, every effect of the thesis's cases — over [0, 0.001]:
// the slider's minimum clamps the negative half); prints, per parameter, the frames per second
// the page achieved (real frames: layout, paint and raster included) and where a redraw's time
// goes: the page's own timings (the core's model, limit cycle and dividing lines, the runs, the
// drawing) and Chromium's (script, style and layout, all tasks of the frame); and the time of a
// 60 s trajectory.  A drag is cut after 30 s (said, with the frames it moved); a drag whose
// values the page refuses (the inline error: e.g. a mesh stiffness without its damping) is said,
// with the message.  With BASELINE_PAGE (e.g. main's build/explorer/index.html) the same drag on
// it, case by case in the same run, and the ratio of the frame rates; with several parameters, a
// last table of the frame rates of every slider × case.
import path from "node:path";
import { findChromium, openBrowser, dragExpression, releaseExpression } from "../tests/explorer/devtools.mjs";

const [page, framesArg = "60", parameterArg = "K", baseline] = process.argv.slice(2);
const frames = Number(framesArg);
const CASES = ["I", "II", "III", "IV", "V", "VI", "VII", "VIII"];
const ALIASES = { b: "backlash", "θR": "reference", thetaR: "reference", theta_R: "reference" };
const chromium = findChromium();
if (!chromium) { console.log("no Chromium installed (apt-get install chromium)"); process.exit(1); }

/// The page open in its own browser, ready.
async function open(file) {
  const b = await openBrowser(chromium);
  await b.cdp("Page.navigate", { url: "file://" + path.resolve(file) });
  await b.waitFor("window.explorer && window.explorer.ready === true && window.explorer.portrait !== null");
  return b;
}

/// The names of the page's sliders (s_NAME): `all`, those of its parameter fields (`parameters`) or of its effects (`effects`).
const SLIDERS = { all: "#fields input[type=range], #effects input[type=range]", parameters: "#fields input[type=range]", effects: "#effects input[type=range]" };
const sliderNames = (b, which) => b.evaluate(`[...document.querySelectorAll(${JSON.stringify(SLIDERS[which])})].map((s) => s.id.slice(2))`);

/// Case `id` on page `b`, slider `name`: three trajectories, then the drag; the frame rate and the timings.
async function measure(b, id, name) {
  await b.evaluate(`document.getElementById("case").value = "${id}"; document.getElementById("case").dispatchEvent(new Event("change"))`);
  await b.frame();
  if (!(await b.evaluate(`document.getElementById("s_${name}") !== null`))) return { missing: true };
  const traj = await b.evaluate(`(() => { const e = window.explorer, w = e.view.x1 - e.view.x0, h = e.view.y1 - e.view.y0, ms = [];
    for (const [x, y] of [[0.25, 0.7], [0.6, 0.3], [0.8, 0.75]]) { e.launch({ theta_o: e.view.x0 + x * w, dtheta_o: e.view.y0 + y * h, flight: false }); ms.push(e.trajectories[e.trajectories.length - 1].ms); }
    return ms; })()`);
  await b.frame();
  const metric = async () => Object.fromEntries((await b.cdp("Performance.getMetrics")).metrics.map((m) => [m.name, m.value]));
  const v0 = await b.evaluate(`document.getElementById("s_${name}").value`);
  const m0 = await metric();
  const r = await b.evaluate(dragExpression(name, frames, 30));
  const m1 = await metric(), per = (k) => (1000 * (m1[k] - m0[k])) / Math.max(1, r.redraws);
  const refused = await b.evaluate(`document.getElementById("status").className === "bad" ? document.getElementById("status").textContent.split("\\n")[0] : ""`);
  await b.evaluate(releaseExpression(name, v0));
  return { ...r, traj, refused, script: per("ScriptDuration"), layout: per("RecalcStyleDuration") + per("LayoutDuration"), tasks: per("TaskDuration") };
}

const b = await open(page);
const base = baseline ? await open(baseline) : null;
try {
  const names = SLIDERS[parameterArg] ? await sliderNames(b, parameterArg) : parameterArg.split(",").map((n) => ALIASES[n.trim()] || n.trim());
  const f = (x) => (x === undefined ? "  -  " : x.toFixed(1).padStart(5));
  const summary = {};
  for (const name of names) {
    console.log(`\n${frames} frames per case, the slider ${name} moved over ±30 % (a value 0: over [0, 0.001]); times per redraw [ms]`);
    console.log(`case  frames/s${base ? "  baseline  ratio" : ""} | model  cycle  dividing  runs  drawing | script  style+layout  all tasks | 60 s trajectory [ms]`);
    summary[name] = {};
    for (const id of CASES) {
      const r = await measure(b, id, name), old = base ? await measure(base, id, name) : null;
      if (r.missing) { console.log(`${id.padEnd(5)} the page has no slider s_${name}`); continue; }
      summary[name][id] = { fps: r.fps, old: old && !old.missing ? old.fps : undefined };
      console.log(`${id.padEnd(5)} ${r.fps.toFixed(1).padStart(8)}` +
        (old ? (old.missing ? "  (no slider)      " : `  ${old.fps.toFixed(1).padStart(8)}  ${(r.fps / old.fps).toFixed(2).padStart(5)}`) : "") +
        ` | ${f(r.load_ms)}  ${f(r.cycle_ms)}  ${f(r.trace_ms).padStart(8)}  ${f(r.runs_ms).padStart(4)}  ${f(r.draw_ms).padStart(7)} | ` +
        `${f(r.script).padStart(6)}  ${f(r.layout).padStart(12)}  ${f(r.tasks).padStart(9)} | ${r.traj.map((x) => x.toFixed(2)).join(", ")}` +
        (r.cut ? `  (cut after ${r.cut} frames: 30 s)` : "") + (r.refused ? `  refused: ${r.refused}` : ""));
    }
  }
  if (names.length > 1) {
    console.log(`\nframes/s per slider × case${base ? " (this page / the baseline)" : ""}; the slowest per slider last`);
    console.log("slider".padEnd(24) + CASES.map((c) => c.padStart(base ? 12 : 7)).join("") + "   min");
    for (const name of names) {
      const row = CASES.map((c) => summary[name][c]);
      const cell = (x) => (!x ? "-" : base ? `${x.fps.toFixed(1)}/${x.old === undefined ? "-" : x.old.toFixed(1)}` : x.fps.toFixed(1));
      const min = Math.min(...row.filter((x) => x).map((x) => x.fps));
      console.log(name.padEnd(24) + row.map((x) => cell(x).padStart(base ? 12 : 7)).join("") + `   ${min.toFixed(1)}`);
    }
  }
  for (const x of [b, base]) if (x && x.pageErrors.length) console.log("page errors: " + x.pageErrors.join("; "));
} finally {
  b.close();
  if (base) base.close();
}
