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
// flight); a bad value shows the inline error naming the field and keeps the drawing; the
// downloads: the figure as SVG (well-formed, with its curves) and PNG (signature, size), the
// trajectory's CSV (`simulate --from … --csv`'s bytes), the case file (`limit-cycle FILE --json`
// gives the peak-to-peak the page shows); a measured record given to the page is overlaid, a
// bad one gives the inline error and keeps the drawing; a screenshot of each thesis case is
// written to ARTIFACT_DIR.  Prints the time of a 60 s trajectory (the redraw rate while a
// slider moves: bench/explorer_redraw.sh).  Exit 77 (ctest SKIP_RETURN_CODE) with the
// reason when there is no Chromium, or when the build makes no page ("not-built": no emcc, or a
// sanitizer build); a page the build should have made and did not is a failure.
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { chromiumForTest, checks, openBrowser } from "./devtools.mjs";

const [page, cli, artifacts, built = "built"] = process.argv.slice(2);
const chromium = chromiumForTest(page, built);
fs.mkdirSync(artifacts, { recursive: true });
const { check, finish } = checks();

const b = await openBrowser(chromium);
const watchdog = setTimeout(() => { console.log("FAIL: the browser test ran over 150 s\n" + b.stderr().slice(-2000)); b.close(); process.exit(1); }, 150000);
const { cdp, evaluate, waitFor, frame } = b;
const requests = [];
b.listeners.push((m) => { if (m.sessionId === b.sessionId && m.method === "Network.requestWillBeSent") requests.push(m.params.request.url); });
await cdp("Network.enable");
const consoleErrors = b.pageErrors;
const backlash = (...args) => JSON.parse(execFileSync(cli, args).toString());
const downloads = fs.mkdtempSync(path.join(os.tmpdir(), "explorer-downloads-"));
const pixels = () => evaluate(`(() => { const p = document.getElementById("plane"); return p.toDataURL ? p.toDataURL() : p.innerHTML; })()`);
/// A part of the checks: an exception in it fails it, and the others still run.
async function part(what, work) {
  try { await work(); } catch (error) { check(what, false, error.message.slice(0, 300)); }
}

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

/// Clicks the page's download button and returns the file it saved (Browser.setDownloadBehavior).
async function downloaded(button, name) {
  const file = path.join(downloads, name);
  fs.rmSync(file, { force: true });
  await evaluate(`document.getElementById("${button}").click()`);
  const until = Date.now() + 10000;
  while (Date.now() < until && !fs.existsSync(file)) await new Promise((r) => setTimeout(r, 50));
  await new Promise((r) => setTimeout(r, 100));  // the file is renamed into place when complete
  return fs.existsSync(file) ? fs.readFileSync(file) : null;
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

  // the dividing lines of both faces: θ̇m0 > 0 (separation from x = −b/2) are `trace V --json`'s
  // points; θ̇m0 < 0 (from x = +b/2) their mirror images about (θR, 0) (the odd symmetry, docs/physics.md)
  await part("the dividing lines", async () => {
    const points = await evaluate("window.explorer.portrait.trace.points");
    const cli = backlash("trace", "V", "--json").points, R = 1, keys = ["theta_m", "dtheta_m", "theta_L", "dtheta_L", "theta_o", "dtheta_o"];
    const positive = points.filter((q) => q.v0 > 0), negative = points.filter((q) => q.v0 < 0);
    let worst = 0, mirrored = 0, same = positive.length === cli.length && negative.length === cli.length;
    for (let i = 0; same && i < cli.length; i++) {
      const m = negative.find((q) => q.v0 === -cli[i].v0);
      same = positive[i].v0 === cli[i].v0 && positive[i].status === cli[i].status && m !== undefined && m.status === cli[i].status;
      if (!same || cli[i].theta_o === null) continue;
      for (const k of keys) {
        worst = Math.max(worst, Math.abs(positive[i][k] - cli[i][k]));
        mirrored = Math.max(mirrored, Math.abs(m[k] - (k.startsWith("d") ? -cli[i][k] : 2 * R - cli[i][k])));
      }
    }
    check("dividing lines of both faces: θ̇m0 > 0 equal `trace V --json`, θ̇m0 < 0 their mirror images about (θR, 0), to 1e-12",
      same && worst <= 1e-12 && mirrored <= 1e-12, `${positive.length} + ${negative.length} points, largest difference ${worst}, from the mirror ${mirrored}`);
  });

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
    const before = await pixels();
    await evaluate(`(() => { const f = document.getElementById("f_${field}"); f.value = ${JSON.stringify(value)}; f.dispatchEvent(new Event("input")); })()`);
    await frame();
    const message = await evaluate(`document.getElementById("e_${field}").textContent`);
    const after = await pixels();
    check(`bad ${field} = '${value}': inline error beside the field, drawing kept`,
      message.length > 0 && message.includes(words) && after === before && after.length > 10000, `message "${message}"`);
    await evaluate(`document.getElementById("case").value = "V"; document.getElementById("case").dispatchEvent(new Event("change"))`);
    await frame();
  }
  await part("the downloads", async () => {
    // the downloads, on case V with another loop gain (a model no case file of the thesis holds)
    await cdp("Browser.setDownloadBehavior", { behavior: "allow", downloadPath: downloads });
    await evaluate(`(() => { const f = document.getElementById("f_K"); f.value = "1.25"; f.dispatchEvent(new Event("input")); })()`);
    await frame();
    await evaluate(`window.explorer.launch({ theta_o: 0.4, dtheta_o: 0.3, flight: false })`);
    const now = await evaluate(`(() => { const e = window.explorer, r = e.trajectories[e.trajectories.length - 1];
      return { p2p: e.portrait.cycle.peak_to_peak, status: document.getElementById("status").textContent, start: r.start, t_end: r.t_end ?? 60, dt: r.dt ?? 60 / 800,
               plane: (({ width, height }) => width + "x" + height)(document.getElementById("plane").getBoundingClientRect()),
             caseFile: e.caseFileName ? e.caseFileName() : "Case_V.toml" }; })()`);
    const svg = await downloaded("dl_svg", "phase-plane.svg");
    const parsed = svg && await evaluate(`(() => { const d = new DOMParser().parseFromString(${JSON.stringify(svg?.toString() ?? "")}, "image/svg+xml");
      const n = (sel) => d.querySelectorAll(sel).length;
      return { error: n("parsererror"), root: d.documentElement.nodeName, cycle: n("path.limit-cycle"), separation: n("path.separation"),
               dividing: n("path.dividing"), trajectory: n("path.trajectory"), step: n("path.step"), events: n("circle.event") }; })()`);
    check("download: the figure as SVG, well-formed, with the limit cycle, both separation lines, the dividing lines, the runs and their events",
      parsed && parsed.error === 0 && parsed.root === "svg" && parsed.cycle === 1 && parsed.separation === 2 && parsed.dividing === 6 &&
      parsed.trajectory === 1 && parsed.step === 1 && parsed.events > 10, JSON.stringify(parsed));
    const png = await downloaded("dl_png", "phase-plane.png");
    const [w, h] = now.plane.split("x").map(Number);
    const pngSize = png && png.length > 24 ? [png.readUInt32BE(16), png.readUInt32BE(20)] : null;
    check("download: the figure as PNG (signature, twice the plane's size)",
      png && png.subarray(0, 8).equals(Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a])) && pngSize[0] === Math.round(2 * w) && pngSize[1] === Math.round(2 * h),
      `${png?.length} bytes, ${pngSize?.join(" × ")} for a ${now.plane} plane`);
    const csv = await downloaded("dl_case", now.caseFile) && await downloaded("dl_csv", "trajectory.csv");
    const caseFile = path.join(downloads, now.caseFile);
    const fromCli = fs.existsSync(caseFile) && execFileSync(cli, ["simulate", caseFile, "--from", `${now.start.theta_o},${now.start.dtheta_o}`,
      "--t-end", String(now.t_end), "--dt", String(now.dt), "--csv"]).toString();
    // The same rows as the CLI's (the wasm core's libm rounds a few last bits differently from the
    // native one: the numbers agree to 1e-12 as the events do, t and the mode exactly).
    const rows = (text) => text.trimEnd().split("\n").map((l) => l.split(","));
    const [mine, theirs] = [csv ? rows(csv.toString()) : [], fromCli ? rows(fromCli) : []];
    let worst = 0, same = mine.length === theirs.length && mine.length > 100;
    for (let i = 1; same && i < mine.length; i++) {
      same = mine[i].length === 8 && mine[i][0] === theirs[i][0] && mine[i][7] === theirs[i][7];
      for (let k = 1; k < 7; k++) worst = Math.max(worst, Math.abs(Number(mine[i][k]) - Number(theirs[i][k])));
    }
    const modes = new Set(mine.slice(1).map((r) => r[7]));
    check("download: the trajectory's CSV is `simulate FILE --from θo,θ̇o --t-end T --dt S --csv`'s: header, rows, t and mode equal, values to 1e-12",
      same && worst <= 1e-12 && mine[0]?.join(",") === "t,theta_o,dtheta_o,theta_m,dtheta_m,theta_L,dtheta_L,mode" && modes.has("contact") && modes.has("free"),
      `${mine.length - 1} rows, largest difference ${worst}, modes ${[...modes].join(", ")}`);
    const fileCycle = fs.existsSync(caseFile) && backlash("limit-cycle", caseFile, "--json");
    check("download: the case file is read by the CLI, `limit-cycle FILE --json` gives the peak-to-peak the page shows",
      fileCycle && Math.abs(fileCycle.peak_to_peak - now.p2p) <= 1e-12 && now.status.includes(`peak-to-peak ${now.p2p}`),
      `page ${now.p2p}, CLI ${fileCycle?.peak_to_peak}`);
  });
  await part("a measured record", async () => {
    // a measured record given to the page (the file input of the drop zone), then a bad one
    const { root } = await cdp("DOM.getDocument");
    const { nodeId } = await cdp("DOM.querySelector", { nodeId: root.nodeId, selector: "#record_file" });
    const record = path.resolve(path.dirname(new URL(import.meta.url).pathname), "../../examples/case_V_with_hidden_friction.csv");
    const plain = await pixels();
    await cdp("DOM.setFileInputFiles", { nodeId, files: [record] });
    await waitFor("window.explorer.record !== null", 10);
    const overlay = await evaluate(`(() => { const e = window.explorer;
      return { n: e.record.t.length, plane: e.scene.items.filter((i) => i.cls === "record").length, time: e.timeScene.items.filter((i) => i.cls === "record").length,
               error: document.getElementById("e_record").textContent }; })()`);
    const drawn = await pixels();
    check("a measured record is overlaid on the phase plane and the time panel", overlay.n === 6001 && overlay.plane === 1 && overlay.time === 1 &&
      overlay.error === "" && drawn !== plain, JSON.stringify(overlay));
    const bad = path.join(downloads, "bad_record.csv");
    fs.writeFileSync(bad, "t,theta_out\n" + Array.from({ length: 12 }, (_, i) => `${i === 7 ? 0.05 : i / 100},${i}`).join("\n") + "\n");
    await cdp("DOM.setFileInputFiles", { nodeId, files: [bad] });
    await waitFor(`document.getElementById("e_record").textContent !== ""`, 10);
    const message = await evaluate(`document.getElementById("e_record").textContent`);
    check("a bad record: the inline error names the file, line and column; the drawing is kept",
      message.startsWith("bad_record.csv:9: t:") && message.includes("strictly increasing") && (await pixels()) === drawn, `"${message}"`);
    // dropped on the page (a drop event carrying the file, as a drag from the desktop delivers
    // it): a record without theta_out, then the good one again
    const drop = (name, text) => evaluate(`(() => { const d = new DataTransfer(); d.items.add(new File([${JSON.stringify(text)}], "${name}"));
      document.getElementById("plane").dispatchEvent(new DragEvent("drop", { dataTransfer: d, bubbles: true, cancelable: true })); })()`);
    await drop("no_theta_out.csv", "t,theta_motor\n" + Array.from({ length: 12 }, (_, i) => `${i},${i}`).join("\n") + "\n");
    await waitFor(`document.getElementById("e_record").textContent.startsWith("no_theta_out.csv")`, 10);
    const dropped = await evaluate(`document.getElementById("e_record").textContent`);
    await drop("again.csv", fs.readFileSync(record, "utf8"));
    await waitFor(`window.explorer.record.name === "again.csv"`, 10);
    check("dropped on the page: a record without theta_out gives the inline error, a good one is overlaid",
      dropped.startsWith("no_theta_out.csv:1: theta_out: missing column") && (await evaluate(`document.getElementById("e_record").textContent`)) === "" &&
      (await evaluate("window.explorer.record.t.length")) === 6001, `"${dropped}"`);
  });

  check("no script error on the page", consoleErrors.length === 0, consoleErrors.join("; "));

  await evaluate("window.explorer.record = null");  // the screenshots without the record
  // screenshots of the eight thesis cases, and the redraw rate while a slider moves
  for (const id of ["I", "II", "III", "IV", "V", "VI", "VII", "VIII"]) {
    await evaluate(`document.getElementById("case").value = "${id}"; document.getElementById("case").dispatchEvent(new Event("change"))`);
    await frame();
    await frame();
    const shot = await cdp("Page.captureScreenshot", { format: "png" });
    fs.writeFileSync(path.join(artifacts, `explorer_case_${id}.png`), Buffer.from(shot.data, "base64"));
  }
  check("screenshots of the eight cases written", ["I", "VIII"].every((id) => fs.existsSync(path.join(artifacts, `explorer_case_${id}.png`))), artifacts);
} catch (error) {
  check("the browser session", false, error.message);
}
clearTimeout(watchdog);
b.close();
if (!process.env.KEEP_DOWNLOADS) fs.rmSync(downloads, { recursive: true, force: true });
finish();
