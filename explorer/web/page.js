// page.js — the explorer page: fields, drawing and interaction only.  Every number drawn comes
// from the WebAssembly core (explorer/src/explorer_core.cpp: the facade, the same C++ as the
// CLI); nothing here computes any physics.  CASES (the thesis's case files) and
// createBacklashCore (the core) are inlined by the build (explorer/assemble.cmake).
"use strict";
(async function () {
  const core = await createBacklashCore();
  const $ = (id) => document.getElementById(id);
  const SVGNS = "http://www.w3.org/2000/svg";
  const PARAMS = [  // the case's parameters: Case::from_texts's names, slider ranges as factors of the case's value
    ["Jm", "motor inertia Jm"], ["Fm", "motor friction Fm"], ["JL", "load inertia JL"], ["FL", "load friction FL"],
    ["K", "loop gain K"], ["backlash", "backlash b"], ["reference", "reference θR"], ["step", "step A"], ["t_end", "t_end [s]"]];
  const EFFECTS = JSON.parse(core.effect_table());
  const COLORS = ["#1f77b4", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf"];

  const S = {  // the page's state; window.explorer exposes it to the browser tests
    loaded: null, portrait: null, step: null, trajectories: [], lastStart: null, record: null,
    view: null, errors: {}, slice: null, timings: {}, redraws: 0,
  };
  window.explorer = S;

  // ------------------------------------------------------------------ fields
  function makeRow(parent, name, label) {
    const row = document.createElement("div");
    row.className = "row";
    row.innerHTML = `<label title="${label}">${name}</label><input type="number" step="any" id="f_${name}">` +
      `<input type="range" id="s_${name}" min="0" max="1" step="any"><div class="err" id="e_${name}"></div>`;
    parent.appendChild(row);
    const field = $("f_" + name), slider = $("s_" + name);
    field.addEventListener("input", () => scheduleUpdate(name));
    // While a slider moves the portrait follows it; the live slice (25 limit cycles) follows on release.
    slider.addEventListener("input", () => { S.sliding = true; field.value = String(+Number(slider.value).toPrecision(6)); scheduleUpdate(name); });
    slider.addEventListener("change", () => { S.sliding = false; if ($("slice_live").checked && S.loaded) computeSlice(); });
  }
  for (const [name, label] of PARAMS) makeRow($("fields"), name, label);
  for (const e of EFFECTS) makeRow($("effects"), e.name, `${e.description} [${e.unit}]`);
  for (const id of Object.keys(CASES)) $("case").add(new Option("case " + id, id));
  $("case").add(new Option("custom", "custom"));
  for (const [name] of PARAMS.slice(0, 7)) $("slice_param").add(new Option(name, name));

  function setSliderRange(name, value) {
    const slider = $("s_" + name), v = Number(value);
    const span = v === 0 ? 1 : Math.abs(v);
    slider.min = v >= 0 && name !== "reference" && name !== "step" ? 0 : v - 2 * span;
    slider.max = v + 2 * span;
    slider.value = v;
  }

  function showCase(id) {
    const r = JSON.parse(core.fields_of_case(CASES[id], id));
    if (!r.ok) return setStatus(r.message, true);
    for (const [name] of PARAMS) { $("f_" + name).value = r.fields[name] ?? ""; setSliderRange(name, r.fields[name] ?? 0); }
    for (const e of EFFECTS) { $("f_" + e.name).value = r.fields[e.name] ?? ""; setSliderRange(e.name, r.fields[e.name] ?? 0); }
    $("measured_at").value = r.fields.measured_at;
    S.caseName = r.fields.name;
    S.trajectories = [];
    S.view = null;
    update();
  }

  /// The fields as Case::from_texts's pairs; empty effect fields are the thesis's model.
  function pairs() {
    const out = [["name", S.caseName || "explorer"], ["measured_at", $("measured_at").value]];
    for (const [name] of PARAMS) {
      const v = $("f_" + name).value.trim();
      if (v !== "" || !["step", "t_end"].includes(name)) out.push([name, v]);
    }
    if (out.some(([n]) => n === "step")) out.push(["experiment", "step"]);
    for (const e of EFFECTS) { const v = $("f_" + e.name).value.trim(); if (v !== "") out.push([e.name, v]); }
    return out;
  }

  // ------------------------------------------------------------------ errors and status
  function clearErrors() {
    for (const el of document.querySelectorAll(".err")) el.textContent = "";
    for (const el of document.querySelectorAll("input.bad")) el.classList.remove("bad");
    S.errors = {};
  }
  function fieldOf(argument) {  // the facade's argument or a case file's key → the page's field
    const map = { "motor.J": "Jm", "motor.F": "Fm", "load.J": "JL", "load.F": "FL", "experiment.step": "step",
      "experiment.t_end": "t_end", "t_end": "t_end", "step": "step" };
    if (map[argument]) return map[argument];
    const known = PARAMS.map(([n]) => n).concat(EFFECTS.map((e) => e.name));
    if (known.includes(argument)) return argument;
    const effect = EFFECTS.find((e) => argument.startsWith(e.effect));
    return effect ? effect.name : null;
  }
  function showError(r) {
    const field = fieldOf(r.field || "");
    S.errors[field || "page"] = r.message;
    if (field && $("e_" + field)) { $("e_" + field).textContent = r.message; $("f_" + field).classList.add("bad"); }
    setStatus((field ? "" : "error: ") + r.message + "\n(the last valid picture is kept)", true);
  }
  function setStatus(text, bad) { $("status").textContent = text; $("status").className = bad ? "bad" : ""; }

  // ------------------------------------------------------------------ computing (all in the core)
  let pending = null;
  function scheduleUpdate(changed) {
    if ($("case").value !== "custom" && changed) S.customised = true;
    if (pending) return;
    pending = requestAnimationFrame(() => { pending = null; update(); });
  }

  /// Loads the fields into the core, recomputes the portrait, the step response and the kept
  /// trajectories, and redraws; on bad input only the message changes (the picture is kept).
  function update() {
    const t0 = performance.now();
    const loaded = JSON.parse(core.load_case(JSON.stringify(pairs())));
    S.timings.load_ms = performance.now() - t0;
    clearErrors();
    if (!loaded.ok) return showError(loaded);
    const portrait = JSON.parse(core.portrait());
    if (!portrait.ok) return showError(portrait);
    // ~800 samples a run: the drawing's resolution (the events, exact, come apart from the samples).
    const tEnd = Number($("f_t_end").value) || 60;
    const step = $("f_step").value.trim() !== "" ? JSON.parse(core.step_response(tEnd / 800)) : null;
    if (step && !step.ok) return showError(step);
    S.loaded = loaded; S.portrait = portrait; S.step = step;
    S.trajectories = S.trajectories.map((t) => runFrom(t.start)).filter((t) => t.ok);
    S.timings.compute_ms = performance.now() - t0;
    if (!S.view) S.view = defaultView();
    draw();
    if ($("slice_live").checked && !S.sliding) computeSlice();
    S.timings.update_ms = performance.now() - t0;
    S.redraws++;
    statusLine();
  }

  function runFrom(start) {
    const t_end = Number($("traj_t_end").value) || 60;
    const r = JSON.parse(core.trajectory(start.theta_o, start.dtheta_o, start.flight, t_end, t_end / 800));
    r.start = start;
    return r;
  }

  function statusLine() {
    const c = S.portrait.cycle;
    let text = `${S.loaded.effects === "none" ? "nominal model" : "effects: " + S.loaded.effects}; ` +
      `separation line θo = θR ${S.loaded.cot_phi >= 0 ? "+" : "−"} ${Math.abs(S.loaded.cot_phi).toPrecision(6)}·θ̇o\n`;
    text += c.status === "limit_cycle"
      ? `limit cycle: peak-to-peak ${c.peak_to_peak}, period ${c.period.toPrecision(8)} s, ${c.stable ? "stable" : "unstable"}\n`
      : `no limit cycle (${c.status}): ${c.reason}\n`;
    if (S.step) text += `step response: ${S.step.simulation.status}, ${S.step.simulation.events.length} events, ${S.step.ms.toFixed(2)} ms\n`;
    const last = S.trajectories[S.trajectories.length - 1];
    if (last) text += `last trajectory: ${last.simulation.status}, ${last.simulation.events.length} events, ${last.ms.toFixed(2)} ms` +
      (last.stop_message ? `\n${last.stop_message}` : "") + "\n";
    text += `redraw ${S.timings.update_ms?.toFixed(1)} ms: model ${S.timings.load_ms?.toFixed(1)} ms, portrait ` +
      `${S.portrait.ms.toFixed(1)} ms, runs ${(S.timings.compute_ms - S.timings.load_ms - S.portrait.ms).toFixed(1)} ms, drawing ${S.timings.draw_ms?.toFixed(1)} ms`;
    setStatus(text, false);
  }

  // ------------------------------------------------------------------ the phase plane
  function defaultView() {
    const xs = [], ys = [];
    const add = (cols) => { if (cols) { xs.push(...cols.theta_o); ys.push(...cols.dtheta_o); } };
    add(S.step?.samples); add(S.portrait.orbit);
    const R = S.loaded.parameters.theta_R, b = S.loaded.parameters.backlash;
    xs.push(R - 2 * b, R + 2 * b); ys.push(-b, b);  // at least the backlash around θR
    const x0 = Math.min(...xs), x1 = Math.max(...xs), y0 = Math.min(...ys), y1 = Math.max(...ys);
    const mx = 0.06 * (x1 - x0), my = 0.08 * (y1 - y0);
    return { x0: x0 - mx, x1: x1 + mx, y0: y0 - my, y1: y1 + my };
  }
  /// The plane's box, measured once per drawing (a layout query per point would cost more than the core).
  let planeBox = null;
  function measureBox() { const r = $("plane").getBoundingClientRect(); planeBox = { w: r.width, h: r.height, left: r.left, top: r.top }; return planeBox; }
  function box() { return planeBox || measureBox(); }
  const PAD = { l: 52, r: 10, t: 10, b: 30 };
  function toPixel(x, y) {
    const { w, h } = box(), v = S.view;
    return [PAD.l + (x - v.x0) / (v.x1 - v.x0) * (w - PAD.l - PAD.r), h - PAD.b - (y - v.y0) / (v.y1 - v.y0) * (h - PAD.t - PAD.b)];
  }
  function fromPixel(px, py) {
    const { w, h } = box(), v = S.view;
    return [v.x0 + (px - PAD.l) / (w - PAD.l - PAD.r) * (v.x1 - v.x0), v.y0 + (h - PAD.b - py) / (h - PAD.t - PAD.b) * (v.y1 - v.y0)];
  }
  S.toClient = (x, y) => { const b = measureBox(), [px, py] = toPixel(x, y); return [b.left + px, b.top + py]; };

  function el(parent, name, attrs, text) {
    const e = document.createElementNS(SVGNS, name);
    for (const k in attrs) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    parent.appendChild(e);
    return e;
  }
  function path(parent, xs, ys, attrs) {
    let d = "";
    for (let i = 0; i < xs.length; i++) { const [px, py] = toPixel(xs[i], ys[i]); d += (i ? "L" : "M") + px.toFixed(1) + " " + py.toFixed(1); }
    return el(parent, "path", Object.assign({ d, fill: "none" }, attrs));
  }
  function ticks(a, b, n) {
    const step0 = (b - a) / n, mag = Math.pow(10, Math.floor(Math.log10(step0)));
    const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => s >= step0);
    const out = [];
    for (let t = Math.ceil(a / step) * step; t <= b; t += step) out.push(Math.abs(t) < step * 1e-9 ? 0 : t);
    return out;
  }
  function axes(g, w, h, v, xlabel, ylabel, toP) {
    el(g, "rect", { x: PAD.l, y: PAD.t, width: w - PAD.l - PAD.r, height: h - PAD.t - PAD.b, fill: "white", stroke: "#999" });
    for (const t of ticks(v.x0, v.x1, 8)) { const [px] = toP(t, v.y0); el(g, "line", { x1: px, x2: px, y1: PAD.t, y2: h - PAD.b, stroke: "#eee" }); el(g, "text", { x: px, y: h - PAD.b + 13, "text-anchor": "middle" }, +t.toPrecision(4)); }
    for (const t of ticks(v.y0, v.y1, 6)) { const [, py] = toP(v.x0, t); el(g, "line", { x1: PAD.l, x2: w - PAD.r, y1: py, y2: py, stroke: "#eee" }); el(g, "text", { x: PAD.l - 4, y: py + 4, "text-anchor": "end" }, +t.toPrecision(4)); }
    el(g, "text", { x: w - PAD.r - 4, y: h - 4, "text-anchor": "end" }, xlabel);
    el(g, "text", { x: 4, y: PAD.t + 10 }, ylabel);
  }

  function draw() {
    const t0 = performance.now();
    const svg = $("plane"), { w, h } = measureBox(), v = S.view, p = S.loaded.parameters;
    const timeBox = $("timeplot").getBoundingClientRect();  // measured before the drawing changes the layout
    svg.innerHTML = "";
    svg.setAttribute("viewBox", `0 0 ${w} ${h}`);
    el(svg, "rect", { width: w, height: h, fill: "white" });
    axes(svg, w, h, v, "θo [rad]", "θ̇o [rad/s]", toPixel);
    const clip = el(el(svg, "defs", {}), "clipPath", { id: "clip" });
    el(clip, "rect", { x: PAD.l, y: PAD.t, width: w - PAD.l - PAD.r, height: h - PAD.t - PAD.b });
    const g = el(svg, "g", { "clip-path": "url(#clip)" });
    const R = p.theta_R, Y = [v.y0 - (v.y1 - v.y0), v.y1 + (v.y1 - v.y0)];
    for (const iso of S.loaded.isoclines)  // θ̇o = slope·(θR − θo), from the core's table
      path(g, [R - Y[0] / iso.slope, R - Y[1] / iso.slope], Y, { stroke: "#d0d0d0", "stroke-width": 1 });
    const c = S.loaded.cot_phi;  // the separation line θo = θR + cot φ·θ̇o: its half leaving each face
    path(g, [R, R + c * Y[1]], [0, Y[1]], { stroke: "#ff7f0e", "stroke-width": 1.6 });
    path(g, [R, R + c * Y[0]], [0, Y[0]], { stroke: "#d62728", "stroke-width": 1.6, "stroke-dasharray": "6 3" });
    drawDividingLines(g);
    if (S.portrait.orbit) path(g, S.portrait.orbit.theta_o, S.portrait.orbit.dtheta_o, { stroke: "#e00", "stroke-width": 2.4 });
    if (S.record) path(g, S.record.thetaForPlane, S.record.dtheta, { stroke: "#000", "stroke-width": 1, "stroke-dasharray": "2 2" });
    if (S.step) drawRun(g, S.step, "#555", 1.2);
    S.trajectories.forEach((t, i) => drawRun(g, t, COLORS[i % COLORS.length], 1.6));
    el(g, "circle", { cx: toPixel(R, 0)[0], cy: toPixel(R, 0)[1], r: 3, fill: "#000" });
    legend();
    drawTime(timeBox);
    drawEvents();
    S.timings.draw_ms = performance.now() - t0;
  }
  function drawDividingLines(g) {  // trace: recombination (or recontact) states after the impact, per sign of θ̇m0
    const pts = S.portrait.trace.points.filter((q) => q.theta_o !== null);
    const groups = {};
    for (const q of pts) (groups[(q.v0 > 0 ? "+" : "−") + q.status] ||= []).push(q);
    const styles = ["#6a3d9a", "#b15928", "#33a02c", "#a6cee3"];
    Object.keys(groups).sort().forEach((k, i) => {
      const q = groups[k].sort((a, b) => a.v0 - b.v0);
      path(g, q.map((x) => x.theta_o), q.map((x) => x.dtheta_o), { stroke: styles[i % 4], "stroke-width": 1.3, "stroke-dasharray": "1 2", class: "dividing" });
    });
    S.dividingGroups = Object.keys(groups).sort();
  }
  function drawRun(g, run, color, width) {
    path(g, run.samples.theta_o, run.samples.dtheta_o, { stroke: color, "stroke-width": width });
    for (const e of run.simulation.events) {
      const [px, py] = toPixel(e.theta_o, e.dtheta_o);
      el(g, "circle", { cx: px, cy: py, r: 2.6, fill: "white", stroke: color }).appendChild(document.createElementNS(SVGNS, "title")).textContent =
        `${e.kind} t = ${e.t}`;
    }
  }
  function legend() {
    const c = S.portrait.cycle;
    $("legend").innerHTML = `<span style="color:#ff7f0e">━</span> separation line (leaving x = −b/2) ` +
      `<span style="color:#d62728">╍</span> (leaving x = +b/2) <span style="color:#6a3d9a">┈</span> dividing lines ` +
      `<span style="color:#d0d0d0">━</span> isoclines <span style="color:#555">━</span> step response ` +
      (c.status === "limit_cycle" ? `<span style="color:#e00">━</span> limit cycle (peak-to-peak ${c.peak_to_peak.toPrecision(6)})`
        : `<b>no limit cycle</b>: ${c.status} — ${c.reason}`);
  }

  // ------------------------------------------------------------------ the time panel and the events
  function drawTime(r) {
    const svg = $("timeplot"), w = r.width, h = r.height;
    svg.innerHTML = "";
    const run = S.trajectories[S.trajectories.length - 1] || S.step;
    if (!run || w === 0) return;
    const s = run.samples, all = s.theta_o.concat(s.theta_m, s.theta_L, S.record ? S.record.theta : []);
    const v = { x0: 0, x1: Math.max(s.t[s.t.length - 1], 1e-9), y0: Math.min(...all), y1: Math.max(...all) };
    if (v.y1 === v.y0) v.y1 = v.y0 + 1;
    const toP = (x, y) => [PAD.l + (x - v.x0) / (v.x1 - v.x0) * (w - PAD.l - PAD.r), h - PAD.b - (y - v.y0) / (v.y1 - v.y0) * (h - PAD.t - PAD.b)];
    axes(svg, w, h, v, "t [s]", "rad", toP);
    const line = (xs, ys, color, dash) => {
      let d = ""; for (let i = 0; i < xs.length; i++) { const [px, py] = toP(xs[i], ys[i]); d += (i ? "L" : "M") + px.toFixed(1) + " " + py.toFixed(1); }
      el(svg, "path", { d, fill: "none", stroke: color, "stroke-width": 1.3, "stroke-dasharray": dash || "" });
    };
    line(s.t, s.theta_m, "#2ca02c"); line(s.t, s.theta_L, "#9467bd", "4 2"); line(s.t, s.theta_o, "#1f77b4");
    if (S.record) line(S.record.t, S.record.theta, "#000", "2 2");
    el(svg, "text", { x: PAD.l + 6, y: PAD.t + 12 }, "θo (blue), θm (green), θL (purple, dashed)" + (S.record ? ", record (black)" : ""));
  }
  function drawEvents() {
    const run = S.trajectories[S.trajectories.length - 1] || S.step;
    if (!run || run === S.eventsShown) return;  // the table is rebuilt only for another run
    S.eventsShown = run;
    const sim = run.simulation;
    $("traj_info").textContent = S.trajectories.length ? `from θo = ${run.start.theta_o}, θ̇o = ${run.start.dtheta_o}` +
      ` (${run.start.flight ? "free flight" : "contact"}): ${sim.status}` : `(step response): ${sim.status}`;
    let html = "<tr><th>t [s]</th><th>kind</th><th>θo</th><th>θ̇o</th><th>θm</th><th>θL</th></tr>";
    for (const e of sim.events.slice(0, 400))
      html += `<tr><td>${e.t.toFixed(9)}</td><td style="text-align:left">${e.kind}${e.bounce ? " (bounce)" : ""}</td>` +
        `<td>${e.theta_o.toFixed(8)}</td><td>${e.dtheta_o.toFixed(8)}</td><td>${e.theta_m.toFixed(8)}</td><td>${e.theta_L.toFixed(8)}</td></tr>`;
    $("events").innerHTML = html;
  }

  // ------------------------------------------------------------------ interaction: click, hover, zoom, pan
  let drag = null;
  const plane = $("plane");
  plane.addEventListener("mousedown", (ev) => { drag = { x: ev.clientX, y: ev.clientY, view: { ...S.view }, moved: false }; });
  plane.addEventListener("mousemove", (ev) => {
    const b = measureBox(), [x, y] = fromPixel(ev.clientX - b.left, ev.clientY - b.top);
    $("readout").textContent = `θo = ${x.toPrecision(6)}  θ̇o = ${y.toPrecision(6)}`;
    if (!drag) return;
    const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
    if (Math.abs(dx) + Math.abs(dy) > 4) drag.moved = true;
    if (!drag.moved) return;
    const sx = (drag.view.x1 - drag.view.x0) / (b.w - PAD.l - PAD.r), sy = (drag.view.y1 - drag.view.y0) / (b.h - PAD.t - PAD.b);
    S.view = { x0: drag.view.x0 - dx * sx, x1: drag.view.x1 - dx * sx, y0: drag.view.y0 + dy * sy, y1: drag.view.y1 + dy * sy };
    draw();
  });
  plane.addEventListener("mouseup", (ev) => {
    const wasDrag = drag && drag.moved;
    drag = null;
    if (wasDrag || !S.loaded) return;
    const b = measureBox(), [x, y] = fromPixel(ev.clientX - b.left, ev.clientY - b.top);
    launch({ theta_o: x, dtheta_o: y, flight: $("flight").checked });
  });
  plane.addEventListener("wheel", (ev) => {
    ev.preventDefault();
    const b = measureBox(), [x, y] = fromPixel(ev.clientX - b.left, ev.clientY - b.top), f = ev.deltaY > 0 ? 1.15 : 1 / 1.15, v = S.view;
    S.view = { x0: x + (v.x0 - x) * f, x1: x + (v.x1 - x) * f, y0: y + (v.y0 - y) * f, y1: y + (v.y1 - y) * f };
    draw();
  }, { passive: false });
  plane.addEventListener("dblclick", () => { S.view = defaultView(); draw(); });

  function launch(start) {
    S.lastStart = start;
    const r = runFrom(start);
    if (!r.ok) return showError(r);
    S.trajectories.push(r);
    if (S.trajectories.length > 6) S.trajectories.shift();
    S.timings.trajectory_ms = r.ms;
    draw();
    statusLine();
  }
  S.launch = launch;
  S.update = update;
  $("clear").onclick = () => { S.trajectories = []; draw(); statusLine(); };
  $("case").onchange = () => { if ($("case").value !== "custom") showCase($("case").value); };
  $("measured_at").onchange = () => scheduleUpdate("measured_at");
  $("traj_t_end").oninput = () => scheduleUpdate();

  // ------------------------------------------------------------------ the live slice
  function computeSlice() {
    const name = $("slice_param").value, value = Number($("f_" + name).value);
    let from = Number($("slice_from").value), to = Number($("slice_to").value);
    if (!$("slice_from").value || !$("slice_to").value || S.sliceFor !== name) {
      from = value === 0 ? -1 : value * 0.5; to = value === 0 ? 1 : value * 1.5;
      if (name === "reference") { from = value - 1; to = value + 1; }
      $("slice_from").value = +from.toPrecision(6); $("slice_to").value = +to.toPrecision(6); S.sliceFor = name;
    }
    const r = JSON.parse(core.slice(name, from, to, 25));
    if (!r.ok) return;
    S.slice = r;
    const svg = $("slice"), w = 300, h = 150;
    svg.innerHTML = "";
    const ys = r.rows.filter((q) => q.peak_to_peak !== undefined).map((q) => q.peak_to_peak);
    const v = { x0: Math.min(from, to), x1: Math.max(from, to), y0: 0, y1: ys.length ? Math.max(...ys) * 1.1 : 1 };
    const toP = (x, y) => [PAD.l + (x - v.x0) / (v.x1 - v.x0) * (w - PAD.l - PAD.r), h - PAD.b - (y - v.y0) / (v.y1 - v.y0) * (h - PAD.t - PAD.b)];
    axes(svg, w, h, v, name, "peak-to-peak", toP);
    for (const q of r.rows) {
      const [px, py] = toP(q.x, q.peak_to_peak ?? 0);
      el(svg, "circle", { cx: px, cy: py, r: 2.5, fill: q.peak_to_peak !== undefined ? "#e00" : "#999" })
        .appendChild(document.createElementNS(SVGNS, "title")).textContent = `${name} = ${q.x}: ${q.status}${q.reason ? " — " + q.reason : ""}`;
    }
    const [cx] = toP(value, 0);
    el(svg, "line", { x1: cx, x2: cx, y1: PAD.t, y2: h - PAD.b, stroke: "#1f77b4", "stroke-dasharray": "3 2" });
  }
  $("slice_param").onchange = () => computeSlice();
  $("slice_from").onchange = $("slice_to").onchange = () => computeSlice();

  // ------------------------------------------------------------------ downloads and the dropped record
  function download(name, blob) {
    const a = document.createElement("a");
    a.href = URL.createObjectURL(blob); a.download = name; a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 1000);
  }
  const svgText = () => new XMLSerializer().serializeToString($("plane"));
  $("dl_svg").onclick = () => download("phase-plane.svg", new Blob([svgText()], { type: "image/svg+xml" }));
  $("dl_png").onclick = () => {
    const { w, h } = box(), img = new Image(), url = URL.createObjectURL(new Blob([svgText()], { type: "image/svg+xml" }));
    img.onload = () => {
      const canvas = document.createElement("canvas"); canvas.width = w * 2; canvas.height = h * 2;
      const ctx = canvas.getContext("2d"); ctx.scale(2, 2); ctx.drawImage(img, 0, 0, w, h);
      canvas.toBlob((b) => download("phase-plane.png", b)); URL.revokeObjectURL(url);
    };
    img.src = url;
  };
  $("dl_csv").onclick = () => {  // the columns of `simulate --csv` (mode: contact or free, from the events)
    const run = S.trajectories[S.trajectories.length - 1] || S.step;
    if (!run) return;
    const s = run.samples;
    let text = "t,theta_o,dtheta_o,theta_m,theta_L\n";
    for (let i = 0; i < s.t.length; i++) text += `${s.t[i]},${s.theta_o[i]},${s.dtheta_o[i]},${s.theta_m[i]},${s.theta_L[i]}\n`;
    download("trajectory.csv", new Blob([text], { type: "text/csv" }));
  };
  $("dl_case").onclick = () => S.loaded && download((S.caseName || "case").replace(/\W+/g, "_") + ".toml",
    new Blob([S.loaded.case_file], { type: "application/toml" }));

  /// A measured record (the project's CSV: header t,theta_out[,...]) overlaid on the time panel
  /// and, with its differences, on the phase plane.  Reading a table is no physics.
  function loadRecord(text, name) {
    const lines = text.split(/\r?\n/).filter((l) => l && !l.startsWith("#"));
    const header = lines.shift().split(",").map((x) => x.trim());
    const it = header.indexOf("t"), io = header.indexOf("theta_out");
    if (it < 0 || io < 0) return setStatus(`${name}: no t and theta_out columns`, true);
    const t = [], theta = [];
    for (const l of lines) { const c = l.split(","); const a = Number(c[it]), b = Number(c[io]); if (Number.isFinite(a) && Number.isFinite(b)) { t.push(a); theta.push(b); } }
    const dtheta = theta.map((x, i) => i + 1 < theta.length ? (theta[i + 1] - x) / (t[i + 1] - t[i]) : NaN).slice(0, -1);
    S.record = { name, t, theta, dtheta, thetaForPlane: theta.slice(0, -1) };
    draw();
    setStatus(`record ${name}: ${t.length} samples overlaid`, false);
  }
  S.loadRecord = loadRecord;
  document.body.addEventListener("dragover", (ev) => ev.preventDefault());
  document.body.addEventListener("drop", (ev) => {
    ev.preventDefault();
    const f = ev.dataTransfer.files[0];
    if (f) f.text().then((text) => loadRecord(text, f.name));
  });
  window.addEventListener("resize", () => S.loaded && draw());

  $("case").value = "V";
  showCase("V");
  S.ready = true;
})();
