// explorer_in_chromium (issue 20): the explorer page (build/explorer/index.html) in a real headless
// Chromium, driven over the DevTools protocol with no npm package — Chromium started with
// --remote-debugging-pipe reads NUL-terminated JSON commands on fd 3 and answers on fd 4.
//
//   node run_in_chromium.mjs PAGE BACKLASH_CLI ARTIFACT_DIR [built|not-built]
//
// Checks: the page loads from disk with no request outside the page; case V's limit-cycle
// peak-to-peak shown equals `backlash limit-cycle V --json`'s, and the step response's events
// `backlash simulate V --json`'s, to 1e-12; a scripted click on the phase plane starts the run
// whose events equal `backlash simulate V --from θo,θ̇o` at the clicked state (contact and
// flight); a bad value shows the inline error naming the field and keeps the drawing; a
// screenshot of each thesis case is written to ARTIFACT_DIR.  Prints the measured times (a 60 s
// trajectory, the redraw rate while a slider moves).  Exit 77 (ctest SKIP_RETURN_CODE) with the
// reason when there is no Chromium, or when the build makes no page ("not-built": no emcc, or a
// sanitizer build); a page the build should have made and did not is a failure.
import { spawn, execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";

const [page, cli, artifacts, built = "built"] = process.argv.slice(2);
const SKIP = 77;
const chromium = ["chromium", "chromium-browser", "google-chrome"].map((name) => {
  try { return execFileSync("sh", ["-c", `command -v ${name}`]).toString().trim(); } catch { return ""; }
}).find((p) => p);
if (!chromium) { console.log("SKIP: no Chromium installed (apt-get install chromium; scripts/install-deps.sh)"); process.exit(SKIP); }
if (built === "not-built") {
  console.log("SKIP: this build makes no explorer page (no emcc — apt-get install emscripten — or a sanitizer build)");
  process.exit(SKIP);
}
if (!fs.existsSync(page)) { console.log(`FAIL: the explorer page ${page} is missing`); process.exit(1); }
fs.mkdirSync(artifacts, { recursive: true });

const failures = [];
function check(what, ok, detail) {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}${detail ? ": " + detail : ""}`);
  if (!ok) failures.push(what);
}

// ------------------------------------------------------------------ the DevTools pipe
const profile = fs.mkdtempSync(path.join(os.tmpdir(), "explorer-chromium-"));
const browser = spawn(chromium, ["--headless=new", "--no-sandbox", "--disable-gpu", "--remote-debugging-pipe",
  "--no-first-run", "--no-default-browser-check", "--disable-extensions", "--disable-background-networking",
  "--disable-component-update", "--disable-sync", "--metrics-recording-only", "--window-size=1400,900",
  `--user-data-dir=${profile}`, "about:blank"], { stdio: ["ignore", "ignore", "pipe", "pipe", "pipe"] });
let stderr = "";
browser.stderr.on("data", (d) => { stderr += d; });
const toBrowser = browser.stdio[3], fromBrowser = browser.stdio[4];
let nextId = 1, buffer = "";
const waiting = new Map(), listeners = [];
fromBrowser.on("data", (chunk) => {
  buffer += chunk.toString();
  let end;
  while ((end = buffer.indexOf("\0")) >= 0) {
    const message = JSON.parse(buffer.slice(0, end));
    buffer = buffer.slice(end + 1);
    if (message.id && waiting.has(message.id)) {
      const { resolve, reject, method } = waiting.get(message.id);
      waiting.delete(message.id);
      message.error ? reject(new Error(`${method}: ${message.error.message}`)) : resolve(message.result);
    } else for (const l of listeners) l(message);
  }
});
function send(method, params = {}, sessionId) {
  const id = nextId++;
  toBrowser.write(JSON.stringify({ id, method, params, ...(sessionId ? { sessionId } : {}) }) + "\0");
  return new Promise((resolve, reject) => waiting.set(id, { resolve, reject, method }));
}
const watchdog = setTimeout(() => { console.log("FAIL: the browser test ran over 150 s\n" + stderr.slice(-2000)); browser.kill("SIGKILL"); process.exit(1); }, 150000);

const { targetId } = await send("Target.createTarget", { url: "about:blank" });
const { sessionId } = await send("Target.attachToTarget", { targetId, flatten: true });
const cdp = (method, params) => send(method, params, sessionId);
const requests = [];
listeners.push((m) => { if (m.sessionId === sessionId && m.method === "Network.requestWillBeSent") requests.push(m.params.request.url); });
const consoleErrors = [];
listeners.push((m) => {
  if (m.sessionId === sessionId && m.method === "Runtime.exceptionThrown") consoleErrors.push(m.params.exceptionDetails.text + " " + (m.params.exceptionDetails.exception?.description || ""));
});
await cdp("Network.enable");
await cdp("Runtime.enable");
await cdp("Page.enable");
await cdp("Emulation.setDeviceMetricsOverride", { width: 1400, height: 900, deviceScaleFactor: 1, mobile: false });

async function evaluate(expression) {
  const r = await cdp("Runtime.evaluate", { expression, returnByValue: true, awaitPromise: true });
  if (r.exceptionDetails) throw new Error(`${expression}: ${r.exceptionDetails.exception?.description || r.exceptionDetails.text}`);
  return r.result.value;
}
async function waitFor(expression, seconds = 30) {
  const until = Date.now() + seconds * 1000;
  while (Date.now() < until) {
    if (await evaluate(expression)) return true;
    await new Promise((r) => setTimeout(r, 50));
  }
  throw new Error(`timed out waiting for ${expression}; page errors: ${consoleErrors.join("; ")}`);
}
const frame = () => evaluate("new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))");
const backlash = (...args) => JSON.parse(execFileSync(cli, args).toString());

function sameEvents(what, page, expected, count) {
  const n = count ?? expected.length;
  let worst = 0, kinds = true;
  for (let i = 0; i < n; i++) {
    if (!page[i] || page[i].kind !== expected[i].kind) { kinds = false; break; }
    for (const k of ["t", "theta_o", "dtheta_o", "theta_m", "theta_L"]) worst = Math.max(worst, Math.abs(page[i][k] - expected[i][k]));
  }
  check(what, kinds && page.length >= n && (count !== undefined || page.length === expected.length) && worst <= 1e-12,
    `${n} events, kinds ${kinds ? "equal" : "differ"}, largest difference ${worst}`);
}

// ------------------------------------------------------------------ the checks
try {
  const loadStart = Date.now();
  await cdp("Page.navigate", { url: "file://" + path.resolve(page) });
  await waitFor("window.explorer && window.explorer.ready === true && window.explorer.portrait !== null");
  console.log(`page ready in ${Date.now() - loadStart} ms`);
  const outside = requests.filter((u) => !u.startsWith("file://") && !u.startsWith("data:") && !u.startsWith("blob:"));
  check("loads from disk with no request outside the page", outside.length === 0 && requests.length >= 1,
    `${requests.length} requests, outside: ${outside.join(", ") || "none"}`);

  // case V: the limit cycle shown, the step response's events
  const cycle = backlash("limit-cycle", "V", "--json");
  const shown = await evaluate(`document.getElementById("status").textContent.match(/peak-to-peak ([-0-9.e+]+)/)[1]`);
  check("case V: limit-cycle peak-to-peak shown equals `limit-cycle V --json`", Math.abs(Number(shown) - cycle.peak_to_peak) <= 1e-12,
    `shown ${shown}, CLI ${cycle.peak_to_peak}`);
  const stepEvents = await evaluate("window.explorer.step.simulation.events");
  sameEvents("case V: step-response events equal `simulate V --json`", stepEvents, backlash("simulate", "V", "--json").events);

  // a scripted click on the phase plane, in contact and in flight
  for (const [flight, x, y] of [[false, 0.3, 0.45], [true, 1.6, -0.35]]) {
    if (flight) await evaluate(`document.getElementById("flight").click()`);
    const [cx, cy] = await evaluate(`window.explorer.toClient(${x}, ${y})`);
    for (const type of ["mouseMoved", "mousePressed", "mouseReleased"])
      await cdp("Input.dispatchMouseEvent", { type, x: cx, y: cy, button: "left", clickCount: 1 });
    const start = await evaluate("window.explorer.lastStart");
    const run = await evaluate("window.explorer.trajectories[window.explorer.trajectories.length - 1].simulation");
    const from = `${start.theta_o},${start.dtheta_o}`;
    const expected = backlash("simulate", "V", "--from", from, ...(flight ? ["--flight"] : []), "--json");
    check(`click at (${x}, ${y}) starts at that state`, Math.abs(start.theta_o - x) < 0.01 && Math.abs(start.dtheta_o - y) < 0.01 && start.flight === flight,
      `θo = ${start.theta_o}, θ̇o = ${start.dtheta_o}, ${flight ? "flight" : "contact"}`);
    sameEvents(`click (${flight ? "flight" : "contact"}): first events equal \`simulate V --from ${from}${flight ? " --flight" : ""}\``,
      run.events, expected.events, Math.min(8, expected.events.length));
    check(`click (${flight ? "flight" : "contact"}): start state equals the CLI's`, JSON.stringify(run.from) === JSON.stringify(expected.from));
  }
  await evaluate(`document.getElementById("flight").click()`);

  // measured: a 60 s trajectory, the redraw while a slider moves
  const trajectory = await evaluate(`(() => { const t0 = performance.now(); window.explorer.launch({theta_o: 0.2, dtheta_o: 0.1, flight: false});
    return { wall: performance.now() - t0, core: window.explorer.trajectories[window.explorer.trajectories.length - 1].ms }; })()`);
  console.log(`MEASURED case V: 60 s trajectory from a click: ${trajectory.core.toFixed(2)} ms in the core, ${trajectory.wall.toFixed(2)} ms with the redraw`);

  // a bad value: the inline error naming the field, the drawing kept
  for (const [field, value, words] of [["Jm", "-1", "inertia"], ["K", "", "K"], ["Fm", "-0.5", "friction"]]) {
    const before = await evaluate(`document.getElementById("plane").innerHTML`);
    await evaluate(`(() => { const f = document.getElementById("f_${field}"); f.value = ${JSON.stringify(value)}; f.dispatchEvent(new Event("input")); })()`);
    await frame();
    const message = await evaluate(`document.getElementById("e_${field}").textContent`);
    const after = await evaluate(`document.getElementById("plane").innerHTML`);
    check(`bad ${field} = '${value}': inline error beside the field, drawing kept`,
      message.length > 0 && message.includes(words) && after === before && after.length > 1000, `message "${message}"`);
    await evaluate(`document.getElementById("case").value = "V"; document.getElementById("case").dispatchEvent(new Event("change"))`);
    await frame();
  }
  check("no script error on the page", consoleErrors.length === 0, consoleErrors.join("; "));

  // screenshots of the eight thesis cases, and the redraw rate while a slider moves
  for (const id of ["I", "II", "III", "IV", "V", "VI", "VII", "VIII"]) {
    await evaluate(`document.getElementById("case").value = "${id}"; document.getElementById("case").dispatchEvent(new Event("change"))`);
    await frame();
    const rate = await evaluate(`(() => {
      const e = window.explorer, slider = document.getElementById("s_FL"), n = 12, t = { load: 0, portrait: 0, runs: 0, draw: 0 };
      const v0 = Number(slider.value), t0 = performance.now();
      for (let i = 1; i <= n; i++) {
        slider.value = v0 * (1 + 0.02 * i) + 0.001 * i; slider.dispatchEvent(new Event("input")); e.update();
        t.load += e.timings.load_ms; t.portrait += e.portrait.ms; t.draw += e.timings.draw_ms;
        t.runs += e.timings.compute_ms - e.timings.load_ms - e.portrait.ms;
      }
      const fps = n / ((performance.now() - t0) / 1000);
      const s0 = performance.now(); slider.dispatchEvent(new Event("change")); const slice = performance.now() - s0;
      slider.value = v0; slider.dispatchEvent(new Event("input")); e.update();
      for (const k in t) t[k] /= n;
      return { fps, slice, ...t };
    })()`);
    console.log(`MEASURED case ${id}: slider redraw ${rate.fps.toFixed(1)} frames/s (per frame: model ${rate.load.toFixed(1)} ms, ` +
      `portrait ${rate.portrait.toFixed(1)} ms, step response and trajectories ${rate.runs.toFixed(1)} ms, drawing ${rate.draw.toFixed(1)} ms); ` +
      `live slice on release ${rate.slice.toFixed(0)} ms (25 limit cycles)`);
    await frame();
    const shot = await cdp("Page.captureScreenshot", { format: "png" });
    fs.writeFileSync(path.join(artifacts, `explorer_case_${id}.png`), Buffer.from(shot.data, "base64"));
  }
  check("screenshots of the eight cases written", ["I", "VIII"].every((id) => fs.existsSync(path.join(artifacts, `explorer_case_${id}.png`))), artifacts);
} catch (error) {
  check("the browser session", false, error.message);
}
clearTimeout(watchdog);
browser.kill("SIGKILL");
fs.rmSync(profile, { recursive: true, force: true });
console.log(failures.length ? `${failures.length} check(s) failed` : "all checks passed");
process.exit(failures.length ? 1 : 0);
