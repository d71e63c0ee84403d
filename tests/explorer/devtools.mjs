// devtools.mjs — a small client of headless Chromium's DevTools protocol over a pipe, with no npm
// package: Chromium started with --remote-debugging-pipe reads NUL-terminated JSON commands on
// fd 3 and answers on fd 4.  Used by the browser tests (*_in_chromium.mjs) and the redraw
// benchmark (bench/explorer_redraw.sh).
import { spawn, execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";

/// The system's Chromium (Debian: chromium), or "" when none is installed.
export function findChromium() {
  return ["chromium", "chromium-browser", "google-chrome"].map((name) => {
    try { return execFileSync("sh", ["-c", `command -v ${name}`]).toString().trim(); } catch { return ""; }
  }).find((p) => p) || "";
}

/// A browser test's Chromium: the system's, or the process exits 77 (ctest SKIP_RETURN_CODE) with
/// the reason when none is installed or the build makes no page (`built` = "not-built"), and 1
/// when the page should exist and does not.
export function chromiumForTest(page, built) {
  const chromium = findChromium();
  if (!chromium) { console.log("SKIP: no Chromium installed (apt-get install chromium; scripts/install-deps.sh)"); process.exit(77); }
  if (built === "not-built") {
    console.log("SKIP: this build makes no explorer page (no emcc — apt-get install emscripten — or a sanitizer build)");
    process.exit(77);
  }
  if (!fs.existsSync(page)) { console.log(`FAIL: the explorer page ${page} is missing`); process.exit(1); }
  return chromium;
}

/// A test's checks: check(what, ok, detail) prints one "ok"/"FAIL" line; finish() prints the
/// count of failed checks and exits 1 when any failed, else 0.
export function checks() {
  const failures = [];
  return {
    check(what, ok, detail) {
      console.log(`${ok ? "ok  " : "FAIL"} ${what}${detail ? ": " + detail : ""}`);
      if (!ok) failures.push(what);
    },
    finish() {
      console.log(failures.length ? `${failures.length} check(s) failed` : "all checks passed");
      process.exit(failures.length ? 1 : 0);
    },
  };
}

/// The page's dividing-line points of θ̇m0 > 0 against `trace FILE --json`'s points: `same` when
/// both list the same θ̇m0 with the same statuses (and, with `decided`, none is work_limit and
/// the list is not empty); `worst` the largest difference of the states relative to max(1, |x|).
export function compareDividingLines(pagePoints, tracePoints, decided = false) {
  const mine = pagePoints.filter((q) => q.v0 > 0);
  let worst = 0, same = mine.length === tracePoints.length && (!decided || tracePoints.length > 0);
  for (let i = 0; same && i < tracePoints.length; i++) {
    const t = tracePoints[i];
    same = mine[i].v0 === t.v0 && mine[i].status === t.status && !(decided && t.status === "work_limit");
    for (const k of ["t", "theta_m", "dtheta_m", "theta_L", "dtheta_L", "theta_o", "dtheta_o"])
      if (same && t[k] !== null) worst = Math.max(worst, Math.abs(mine[i][k] - t[k]) / Math.max(1, Math.abs(t[k])));
  }
  return { count: mine.length, same, worst };
}

/// Starts headless Chromium and opens one page (a 1400×900 window); returns { cdp, evaluate,
/// waitFor, frame, listeners, sessionId, close, stderr() }.  cdp(method, params) sends a
/// command to the page's session; listeners receive every event.
export async function openBrowser(chromium) {
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
  const send = (method, params = {}, sessionId) => {
    const id = nextId++;
    toBrowser.write(JSON.stringify({ id, method, params, ...(sessionId ? { sessionId } : {}) }) + "\0");
    return new Promise((resolve, reject) => waiting.set(id, { resolve, reject, method }));
  };
  const { targetId } = await send("Target.createTarget", { url: "about:blank" });
  const { sessionId } = await send("Target.attachToTarget", { targetId, flatten: true });
  const cdp = (method, params) => send(method, params, sessionId);
  const pageErrors = [];
  listeners.push((m) => {
    if (m.sessionId === sessionId && m.method === "Runtime.exceptionThrown")
      pageErrors.push(m.params.exceptionDetails.text + " " + (m.params.exceptionDetails.exception?.description || ""));
  });
  await cdp("Runtime.enable");
  await cdp("Page.enable");
  await cdp("Performance.enable");
  await cdp("Emulation.setDeviceMetricsOverride", { width: 1400, height: 900, deviceScaleFactor: 1, mobile: false });

  async function evaluate(expression) {
    const r = await cdp("Runtime.evaluate", { expression, returnByValue: true, awaitPromise: true });
    if (r.exceptionDetails) throw new Error(`${expression.slice(0, 200)}: ${r.exceptionDetails.exception?.description || r.exceptionDetails.text}`);
    return r.result.value;
  }
  async function waitFor(expression, seconds = 30) {
    const until = Date.now() + seconds * 1000;
    while (Date.now() < until) {
      if (await evaluate(expression)) return true;
      await new Promise((r) => setTimeout(r, 50));
    }
    throw new Error(`timed out waiting for ${expression}; page errors: ${pageErrors.join("; ")}`);
  }
  const frame = () => evaluate("new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))");
  function close() {
    browser.kill("SIGKILL");
    try { fs.rmSync(profile, { recursive: true, force: true, maxRetries: 5 }); } catch { /* Chromium still closing: a temporary folder left */ }
  }
  return { send, cdp, evaluate, waitFor, frame, listeners, sessionId, pageErrors, close, stderr: () => stderr };
}

/// The explorer page's own drag of a parameter's slider, as a user's: each animation frame
/// moves the slider (an input event), the page redraws on its next frame.  `frames` redraws;
/// returns the frames per second and the page's mean timings per redraw.  The slider is left
/// where it is, still "sliding" (the caller releases it: releaseExpression).  With `seconds`, the
/// drag ends early when it has taken that long (cut: the frames moved).
export function dragExpression(name, frames, seconds = Infinity) {
  return `new Promise((done) => {
    const e = window.explorer, slider = document.getElementById("s_${name}"), v0 = Number(slider.value);
    const sums = {}; let i = 0, t0 = 0, first = e.redraws;
    const tick = () => {
      if (e.redraws > first) for (const [k, v] of Object.entries(e.timings)) sums[k] = (sums[k] || 0) + v;
      if (i === 0) t0 = performance.now();
      if (i === ${frames} || (i > 0 && performance.now() - t0 > ${seconds} * 1000)) {
        const seconds = (performance.now() - t0) / 1000, n = e.redraws - first;
        for (const k in sums) sums[k] /= n;
        return done({ fps: n / seconds, redraws: n, ...(i < ${frames} ? { cut: i } : {}), ...sums });
      }
      i++;
      slider.value = v0 * (1 + 0.3 * Math.sin(i / 6)) + 0.001 * Math.sin(i / 6); slider.dispatchEvent(new Event("input"));
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  })`;
}

/// Puts the slider back and releases it (the change event: the exact limit cycle, the live slice).
export const releaseExpression = (name, value) => `(() => { const s = document.getElementById("s_${name}");
  s.value = ${value}; s.dispatchEvent(new Event("input")); s.dispatchEvent(new Event("change")); })()`;
