// page.js — the explorer page: fields, drawing and interaction only.  Every number drawn comes
// from the WebAssembly core (explorer/src/explorer_core.cpp: the facade, the same C++ as the
// CLI); nothing here computes any physics.  CASES (the thesis's case files) and
// createBacklashCore (the core) are inlined by the build (explorer/assemble.cmake).
"use strict";
(async function () {
  const core = await createBacklashCore();
  const $ = (id) => document.getElementById(id);
  const PARAMS = [  // the case's parameters: Case::from_texts's names, slider ranges as factors of the case's value
    ["Jm", "motor inertia Jm"], ["Fm", "motor friction Fm"], ["JL", "load inertia JL"], ["FL", "load friction FL"],
    ["K", "loop gain K"], ["backlash", "backlash b"], ["reference", "reference θR"], ["step", "step A"], ["t_end", "t_end [s]"]];
  const EFFECTS = JSON.parse(core.effect_table());
  const COLORS = ["#9467bd", "#17becf", "#8c564b", "#e377c2", "#bcbd22", "#7f7f7f"];  // apart from the loci's blue, green, red

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
    // On release the table of events (left alone while sliding: text is costly to lay out and paint
    // every frame) and the live slice (25 limit cycles) follow.
    slider.addEventListener("change", () => { S.sliding = false; if (S.loaded) { drawEvents(); if ($("slice_live").checked) computeSlice(); } });
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
  /// What the portrait and the trajectories depend on: every field but the step experiment's
  /// (step, t_end) — with effects the step seeds the cycle search, so it counts there too.
  function portraitKey(p) {
    const effects = EFFECTS.some((e) => $("f_" + e.name).value.trim() !== "");
    return JSON.stringify(effects ? p : p.filter(([n]) => !["step", "t_end", "experiment"].includes(n))) + "|" + $("traj_t_end").value;
  }
  /// The columns a run left in the core's memory (explorer_core.cpp, samples()): copied once
  /// into a Float64Array, then t, θo, θ̇o, θm, θL as views of it — no JSON for the samples.
  function columns(name, n) {
    const a = core.samples(name).slice(), col = (k) => a.subarray(k * n, (k + 1) * n);
    return { t: col(0), theta_o: col(1), dtheta_o: col(2), theta_m: col(3), theta_L: col(4) };
  }
  function update() {
    const t0 = performance.now(), fields = pairs(), key = portraitKey(fields);
    const loaded = JSON.parse(core.load_case(JSON.stringify(fields)));
    S.timings.load_ms = performance.now() - t0;
    clearErrors();
    if (!loaded.ok) return showError(loaded);
    // Only a change the portrait depends on recomputes it (and the trajectories): not the step's.
    const same = key === S.portraitKey && S.portrait;
    const portrait = same ? S.portrait : JSON.parse(core.portrait());
    if (!portrait.ok) return showError(portrait);
    if (!same) portrait.orbit = portrait.orbit ? columns("orbit", portrait.orbit) : null;
    const t1 = performance.now();
    // ~800 samples a run: the drawing's resolution (the events, exact, come apart from the samples).
    const tEnd = Number($("f_t_end").value) || 60;
    const step = $("f_step").value.trim() !== "" ? sampled(JSON.parse(core.step_response(tEnd / 800))) : null;
    if (step && !step.ok) return showError(step);
    if (step) step.dt = tEnd / 800;
    S.loaded = loaded; S.portrait = portrait; S.step = step; S.portraitKey = key;
    if (!same) S.trajectories = S.trajectories.map((t) => runFrom(t.start)).filter((t) => t.ok);
    S.timings.compute_ms = performance.now() - t0;
    Object.assign(S.timings, { cycle_ms: same ? 0 : portrait.cycle_ms, trace_ms: same ? 0 : portrait.trace_ms,
      portrait_ms: t1 - t0 - S.timings.load_ms, runs_ms: performance.now() - t1 });
    if (!S.view) S.view = defaultView();
    draw();
    if ($("slice_live").checked && !S.sliding) computeSlice();
    S.timings.update_ms = performance.now() - t0;
    S.redraws++;
    statusLine();
  }

  function sampled(r) { if (r.ok) r.samples = columns("run", r.count); return r; }
  function runFrom(start) {
    const t_end = Number($("traj_t_end").value) || 60;
    const r = sampled(JSON.parse(core.trajectory(start.theta_o, start.dtheta_o, start.flight, t_end, t_end / 800)));
    Object.assign(r, { start, t_end, dt: t_end / 800 });
    return r;
  }

  function statusLine() {
    const c = S.portrait.cycle;
    let text = `${S.loaded.effects === "none" ? "nominal model" : "effects: " + S.loaded.effects}; ` +
      `separation line θo = θR ${S.loaded.cot_phi >= 0 ? "+" : "−"} ${Math.abs(S.loaded.cot_phi).toPrecision(6)}·θ̇o\n`;
    text += c.status === "limit_cycle"
      ? `limit cycle: peak-to-peak ${c.peak_to_peak}, period ${c.period.toPrecision(8)} s, ${c.stable ? "stable" : "unstable"}\n`
      : `no limit cycle (${c.status}): ${c.reason}\n`;
    const tr = S.portrait.trace;
    if (tr.work_limit) {  // trace's points its search could not decide (status work_limit), as the CLI's exit 3
      const n = tr.points.filter((q) => q.status === "work_limit").length;
      text += `dividing lines: ${n} of ${tr.points.length} points undecided (work_limit): ${tr.work_limit}\n`;
    }
    if (S.step) text += `step response: ${S.step.simulation.status}, ${S.step.simulation.events.length} events, ${S.step.ms.toFixed(2)} ms\n`;
    const last = S.trajectories[S.trajectories.length - 1];
    if (last) text += `last trajectory: ${last.simulation.status}, ${last.simulation.events.length} events, ${last.ms.toFixed(2)} ms` +
      (last.stop_message ? `\n${last.stop_message}` : "") + "\n";
    text += `redraw ${S.timings.update_ms?.toFixed(1)} ms: model ${S.timings.load_ms?.toFixed(1)} ms, portrait ` +
      `${S.timings.portrait_ms?.toFixed(1)} ms, runs ${S.timings.runs_ms?.toFixed(1)} ms, drawing ${S.timings.draw_ms?.toFixed(1)} ms`;
    setStatus(text, false);
  }

  // ------------------------------------------------------------------ scenes: one drawing, two renderings
  /// A drawing as a list of items in pixels — polylines (each one Path2D on the canvas), dots,
  /// texts, rectangles — painted on a canvas (the live view: no DOM node per curve or point) or
  /// written as SVG text (the download).  Items with `clip` are clipped to the scene's plot box.
  function scene(w, h) { return { w, h, items: [], clip: { x: PAD.l, y: PAD.t, w: w - PAD.l - PAD.r, h: h - PAD.t - PAD.b } }; }
  /// A curve through (xs[i], ys[i]) in data coordinates, mapped by toP; `pairs`: separate segments.
  function curve(sc, xs, ys, toP, style) {
    const n = xs.length, px = new Float32Array(n), py = new Float32Array(n);
    for (let i = 0; i < n; i++) { const q = toP(xs[i], ys[i]); px[i] = q[0]; py[i] = q[1]; }
    sc.items.push(Object.assign({ kind: "line", px, py, clip: true }, style));
  }
  function dots(sc, xs, ys, toP, style) {
    const n = xs.length, px = new Float32Array(n), py = new Float32Array(n);
    for (let i = 0; i < n; i++) { const q = toP(xs[i], ys[i]); px[i] = q[0]; py[i] = q[1]; }
    sc.items.push(Object.assign({ kind: "dots", px, py, clip: true }, style));
  }
  const text = (sc, x, y, str, anchor) => sc.items.push({ kind: "text", x, y, str: String(str), anchor: anchor || "start" });

  function tracePath(target, it) {
    const { px, py } = it;
    for (let i = 0; i < px.length; i++) {
      if (it.pairs ? i % 2 === 0 : i === 0) target.moveTo(px[i], py[i]); else target.lineTo(px[i], py[i]);
    }
  }
  function paint(canvas, sc) {
    const dpr = window.devicePixelRatio || 1, W = Math.round(sc.w * dpr), H = Math.round(sc.h * dpr);
    if (canvas.width !== W || canvas.height !== H) { canvas.width = W; canvas.height = H; }
    paintOn(canvas.getContext("2d"), sc, dpr);
  }
  function paintOn(ctx, sc, scale) {
    ctx.setTransform(scale, 0, 0, scale, 0, 0);
    ctx.clearRect(0, 0, sc.w, sc.h);
    ctx.fillStyle = "white"; ctx.fillRect(0, 0, sc.w, sc.h);
    ctx.font = "11px system-ui, sans-serif";
    for (const it of sc.items) {
      ctx.save();
      if (it.clip) { ctx.beginPath(); ctx.rect(sc.clip.x, sc.clip.y, sc.clip.w, sc.clip.h); ctx.clip(); }
      if (it.kind === "rect") {
        ctx.fillStyle = it.fill; ctx.fillRect(it.x, it.y, it.w, it.h); ctx.strokeStyle = it.stroke; ctx.strokeRect(it.x, it.y, it.w, it.h);
      } else if (it.kind === "line") {
        const p = new Path2D(); tracePath(p, it);
        ctx.strokeStyle = it.stroke; ctx.lineWidth = it.width || 1; ctx.setLineDash(it.dash || []); ctx.stroke(p);
      } else if (it.kind === "dots") {
        const p = new Path2D();
        for (let i = 0; i < it.px.length; i++) { p.moveTo(it.px[i] + it.r, it.py[i]); p.arc(it.px[i], it.py[i], it.r, 0, 2 * Math.PI); }
        ctx.fillStyle = it.fill; ctx.fill(p);
        if (it.stroke) { ctx.strokeStyle = it.stroke; ctx.lineWidth = 1; ctx.stroke(p); }
      } else if (it.kind === "text") {
        ctx.fillStyle = "#000"; ctx.textAlign = it.anchor === "middle" ? "center" : it.anchor === "end" ? "right" : "left"; ctx.fillText(it.str, it.x, it.y);
      }
      ctx.restore();
    }
  }
  const xml = (s) => String(s).replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/"/g, "&quot;");
  /// The scene as an SVG document (the figure download); `caption`: the legend, a line on top.
  function svgOf(sc, caption) {
    const f = (x) => (Math.round(x * 10) / 10).toString();
    let out = `<svg xmlns="http://www.w3.org/2000/svg" width="${sc.w}" height="${sc.h + 16}" viewBox="0 -16 ${sc.w} ${sc.h + 16}">\n` +
      `<defs><clipPath id="clip"><rect x="${sc.clip.x}" y="${sc.clip.y}" width="${sc.clip.w}" height="${sc.clip.h}"/></clipPath></defs>\n` +
      `<rect x="0" y="-16" width="${sc.w}" height="${sc.h + 16}" fill="white"/>\n` +
      `<text x="4" y="-4" font-family="sans-serif" font-size="11">${xml(caption)}</text>\n`;
    for (const it of sc.items) {
      const clip = it.clip ? ` clip-path="url(#clip)"` : "", cls = it.cls ? ` class="${it.cls}"` : "";
      if (it.kind === "rect") out += `<rect x="${it.x}" y="${it.y}" width="${it.w}" height="${it.h}" fill="${it.fill}" stroke="${it.stroke}"/>\n`;
      else if (it.kind === "line") {
        let d = "";
        for (let i = 0; i < it.px.length; i++) d += ((it.pairs ? i % 2 === 0 : i === 0) ? "M" : "L") + f(it.px[i]) + " " + f(it.py[i]);
        out += `<path${cls} d="${d}" fill="none" stroke="${it.stroke}" stroke-width="${it.width || 1}"` +
          (it.dash ? ` stroke-dasharray="${it.dash.join(" ")}"` : "") + `${clip}/>\n`;
      } else if (it.kind === "dots") {
        for (let i = 0; i < it.px.length; i++)
          out += `<circle${cls} cx="${f(it.px[i])}" cy="${f(it.py[i])}" r="${it.r}" fill="${it.fill}"${it.stroke ? ` stroke="${it.stroke}"` : ""}${clip}/>\n`;
      } else if (it.kind === "text")
        out += `<text x="${f(it.x)}" y="${f(it.y)}" text-anchor="${it.anchor}" font-family="sans-serif" font-size="11">${xml(it.str)}</text>\n`;
    }
    return out + "</svg>\n";
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
  /// The map of a view v onto a w × h box (data → pixels), and back.
  const mapping = (v, w, h) => (x, y) => [PAD.l + (x - v.x0) / (v.x1 - v.x0) * (w - PAD.l - PAD.r), h - PAD.b - (y - v.y0) / (v.y1 - v.y0) * (h - PAD.t - PAD.b)];
  function toPixel(x, y) { const { w, h } = box(); return mapping(S.view, w, h)(x, y); }
  function fromPixel(px, py) {
    const { w, h } = box(), v = S.view;
    return [v.x0 + (px - PAD.l) / (w - PAD.l - PAD.r) * (v.x1 - v.x0), v.y0 + (h - PAD.b - py) / (h - PAD.t - PAD.b) * (v.y1 - v.y0)];
  }
  S.toClient = (x, y) => { const b = measureBox(), [px, py] = toPixel(x, y); return [b.left + px, b.top + py]; };

  function ticks(a, b, n) {
    const step0 = (b - a) / n, mag = Math.pow(10, Math.floor(Math.log10(step0)));
    const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => s >= step0);
    const out = [];
    for (let t = Math.ceil(a / step) * step; t <= b; t += step) out.push(Math.abs(t) < step * 1e-9 ? 0 : t);
    return out;
  }
  function axes(sc, v, xlabel, ylabel, toP) {
    const { w, h } = sc, gx = [], gy = [];
    sc.items.push({ kind: "rect", x: PAD.l, y: PAD.t, w: w - PAD.l - PAD.r, h: h - PAD.t - PAD.b, fill: "white", stroke: "#999" });
    for (const t of ticks(v.x0, v.x1, 8)) { const [px] = toP(t, v.y0); gx.push(px, px); gy.push(PAD.t, h - PAD.b); text(sc, px, h - PAD.b + 13, +t.toPrecision(4), "middle"); }
    for (const t of ticks(v.y0, v.y1, 6)) { const [, py] = toP(v.x0, t); gx.push(PAD.l, w - PAD.r); gy.push(py, py); text(sc, PAD.l - 4, py + 4, +t.toPrecision(4), "end"); }
    sc.items.push({ kind: "line", px: Float32Array.from(gx), py: Float32Array.from(gy), pairs: true, stroke: "#eee", cls: "grid" });
    text(sc, w - PAD.r - 4, h - 4, xlabel, "end");
    text(sc, 4, PAD.t + 10, ylabel);
  }

  /// The phase plane as a scene: isoclines, both halves of the separation line, the dividing
  /// lines, the limit cycle, the record, the step response and the trajectories with their events.
  function planeScene(w, h) {
    const v = S.view, p = S.loaded.parameters, sc = scene(w, h), toP = mapping(v, w, h);
    axes(sc, v, "θo [rad]", "θ̇o [rad/s]", toP);
    const R = p.theta_R, Y = [v.y0 - (v.y1 - v.y0), v.y1 + (v.y1 - v.y0)];
    for (const iso of S.loaded.isoclines)  // θ̇o = slope·(θR − θo), from the core's table
      curve(sc, [R - Y[0] / iso.slope, R - Y[1] / iso.slope], Y, toP, { stroke: "#d0d0d0", cls: "isocline" });
    const c = S.loaded.cot_phi;  // the separation line θo = θR + cot φ·θ̇o: its half leaving each face
    curve(sc, [R, R + c * Y[1]], [0, Y[1]], toP, { stroke: "#ff7f0e", width: 1.6, cls: "separation" });
    curve(sc, [R, R + c * Y[0]], [0, Y[0]], toP, { stroke: "#ff7f0e", width: 1.6, dash: [6, 3], cls: "separation" });
    dividingLines(sc, toP);
    if (S.portrait.orbit) curve(sc, S.portrait.orbit.theta_o, S.portrait.orbit.dtheta_o, toP, { stroke: "#e00", width: 2.4, cls: "limit-cycle" });
    if (S.record) curve(sc, S.record.thetaForPlane, S.record.dtheta, toP, { stroke: "#000", dash: [2, 2], cls: "record" });
    if (S.step) run(sc, S.step, "#555", 1.2, toP, "step");
    S.trajectories.forEach((t, i) => run(sc, t, COLORS[i % COLORS.length], 1.6, toP, "trajectory"));
    dots(sc, [R], [0], toP, { r: 3, fill: "#000" });
    return sc;
  }
  function draw() {
    const t0 = performance.now();
    const { w, h } = measureBox(), timeBox = $("timeplot").getBoundingClientRect();  // measured before the drawing changes the layout
    S.scene = planeScene(w, h);
    paint($("plane"), S.scene);
    legend();
    drawTime(timeBox);
    drawEvents();
    S.timings.draw_ms = performance.now() - t0;
  }
  /// The dividing lines (trace at θ̇m0 of both signs: the separation from each face), as the
  /// report draws them: per face, the loci of the motor and of the load just before the impact
  /// and of the recombined state just after it (eq. 24); points that never recombine left out.
  const LOCI = [["motor", "theta_m", "dtheta_m", "#1f5fbf"], ["load", "theta_L", "dtheta_L", "#2a9d3a"], ["recombined", "theta_o", "dtheta_o", "#d62728"]];
  function dividingLines(sc, toP) {
    const pts = S.portrait.trace.points.filter((q) => q.theta_o !== null && q.status !== "none");
    for (const [face, sign] of [["−b/2", 1], ["+b/2", -1]]) {
      const q = pts.filter((x) => Math.sign(x.v0) === sign).sort((a, b) => a.v0 - b.v0);
      for (const [locus, x, y, color] of LOCI)
        curve(sc, q.map((p) => p[x]), q.map((p) => p[y]), toP, { stroke: color, width: locus === "recombined" ? 1.5 : 1.1, dash: locus === "recombined" ? [4, 2] : [1, 2],
          cls: `dividing ${locus}`, face });
    }
  }
  function run(sc, r, color, width, toP, cls) {
    curve(sc, r.samples.theta_o, r.samples.dtheta_o, toP, { stroke: color, width, cls });
    const ev = r.simulation.events;
    dots(sc, ev.map((e) => e.theta_o), ev.map((e) => e.dtheta_o), toP, { r: 2.6, fill: "white", stroke: color, cls: "event" });
  }
  function legendText() {
    const c = S.portrait.cycle;
    return "separation line (orange; leaving x = −b/2: solid, x = +b/2: dashed), dividing lines of both faces (motor blue, load green, " +
      "recombined red dashed), isoclines (grey), step response (dark grey), " +
      (c.status === "limit_cycle" ? `limit cycle (red, peak-to-peak ${c.peak_to_peak.toPrecision(6)})` : `no limit cycle: ${c.status} — ${c.reason}`);
  }
  function legend() {
    const c = S.portrait.cycle;
    $("legend").innerHTML = `<span style="color:#ff7f0e">━</span> separation line (leaving x = −b/2, θ̇o > 0) ` +
      `<span style="color:#ff7f0e">╍</span> (leaving x = +b/2, θ̇o < 0); dividing lines of both faces: <span style="color:#1f5fbf">┈</span> motor ` +
      `<span style="color:#2a9d3a">┈</span> load before the impact <span style="color:#d62728">╍</span> recombined; ` +
      `<span style="color:#d0d0d0">━</span> isoclines <span style="color:#555">━</span> step response ` +
      (c.status === "limit_cycle" ? `<span style="color:#e00">━</span> limit cycle (peak-to-peak ${c.peak_to_peak.toPrecision(6)})`
        : `<b>no limit cycle</b>: ${c.status} — ${c.reason}`);
  }

  // ------------------------------------------------------------------ the time panel and the events
  function range(arrays) {
    let lo = Infinity, hi = -Infinity;
    for (const a of arrays) for (let i = 0; i < a.length; i++) { if (a[i] < lo) lo = a[i]; if (a[i] > hi) hi = a[i]; }
    return [lo, hi];
  }
  function drawTime(r) {
    const canvas = $("timeplot"), w = r.width, h = r.height;
    const last = S.trajectories[S.trajectories.length - 1] || S.step;
    if (!last || w === 0) return;
    const s = last.samples, [y0, y1] = range([s.theta_o, s.theta_m, s.theta_L, S.record ? S.record.theta : []]);
    const v = { x0: 0, x1: Math.max(s.t[s.t.length - 1], 1e-9), y0, y1: y1 === y0 ? y0 + 1 : y1 };
    const sc = scene(w, h), toP = mapping(v, w, h);
    axes(sc, v, "t [s]", "rad", toP);
    curve(sc, s.t, s.theta_m, toP, { stroke: "#2ca02c", width: 1.3 });
    curve(sc, s.t, s.theta_L, toP, { stroke: "#9467bd", width: 1.3, dash: [4, 2] });
    curve(sc, s.t, s.theta_o, toP, { stroke: "#1f77b4", width: 1.3 });
    if (S.record) curve(sc, S.record.t, S.record.theta, toP, { stroke: "#000", width: 1.3, dash: [2, 2], cls: "record" });
    text(sc, PAD.l + 6, PAD.t + 12, "θo (blue), θm (green), θL (purple, dashed)" + (S.record ? ", record (black)" : ""));
    S.timeScene = sc;
    paint(canvas, sc);
  }
  function drawEvents() {
    const run = S.trajectories[S.trajectories.length - 1] || S.step;
    if (!run || run === S.eventsShown || S.sliding) return;  // the table is rebuilt only for another run
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
    $("readout").textContent = `θo = ${x.toPrecision(6)}  θ̇o = ${y.toPrecision(6)}` + nearEvent(ev.clientX - b.left, ev.clientY - b.top);
    if (!drag) return;
    const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
    if (Math.abs(dx) + Math.abs(dy) > 4) drag.moved = true;
    if (!drag.moved) return;
    const sx = (drag.view.x1 - drag.view.x0) / (b.w - PAD.l - PAD.r), sy = (drag.view.y1 - drag.view.y0) / (b.h - PAD.t - PAD.b);
    S.view = { x0: drag.view.x0 - dx * sx, x1: drag.view.x1 - dx * sx, y0: drag.view.y0 + dy * sy, y1: drag.view.y1 + dy * sy };
    draw();
  });
  function nearEvent(px, py) {  // the event marker under the pointer (within 5 px), as its tooltip was
    for (const r of S.trajectories.concat(S.step ? [S.step] : []))
      for (const e of r.simulation.events) {
        const [ex, ey] = toPixel(e.theta_o, e.dtheta_o);
        if (Math.abs(ex - px) < 5 && Math.abs(ey - py) < 5) return `  — ${e.kind} at t = ${e.t}`;
      }
    return "";
  }
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
    const w = 300, h = 150, sc = scene(w, h);
    const ys = r.rows.filter((q) => q.peak_to_peak !== undefined).map((q) => q.peak_to_peak);
    const v = { x0: Math.min(from, to), x1: Math.max(from, to), y0: 0, y1: ys.length ? Math.max(...ys) * 1.1 : 1 }, toP = mapping(v, w, h);
    axes(sc, v, name, "peak-to-peak", toP);
    const found = r.rows.filter((q) => q.peak_to_peak !== undefined), none = r.rows.filter((q) => q.peak_to_peak === undefined);
    dots(sc, found.map((q) => q.x), found.map((q) => q.peak_to_peak), toP, { r: 2.5, fill: "#e00" });
    dots(sc, none.map((q) => q.x), none.map(() => 0), toP, { r: 2.5, fill: "#999" });
    curve(sc, [value, value], [v.y0, v.y1], toP, { stroke: "#1f77b4", dash: [3, 2] });
    paint($("slice"), sc);
  }
  $("slice_param").onchange = () => computeSlice();
  $("slice_from").onchange = $("slice_to").onchange = () => computeSlice();

  // ------------------------------------------------------------------ downloads and the dropped record
  function download(name, blob) {
    const a = document.createElement("a");
    a.href = URL.createObjectURL(blob); a.download = name; a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 1000);
  }
  /// The phase plane as drawn, as SVG (the scene written as text, its legend on top) and as PNG
  /// (the scene painted at twice the size).
  const svgText = () => svgOf(S.scene, legendText());
  S.svgText = svgText;
  $("dl_svg").onclick = () => download("phase-plane.svg", new Blob([svgText()], { type: "image/svg+xml" }));
  $("dl_png").onclick = () => {
    const canvas = document.createElement("canvas");
    canvas.width = Math.round(S.scene.w * 2); canvas.height = Math.round(S.scene.h * 2);
    paintOn(canvas.getContext("2d"), S.scene, 2);
    canvas.toBlob((b) => download("phase-plane.png", b));
  };
  /// The last trajectory (else the step response) as `simulate --from … --csv` (`simulate CASE
  /// --csv`) writes it, byte for byte: the core computes it again with the run's own request.
  $("dl_csv").onclick = () => {
    const run = S.trajectories[S.trajectories.length - 1] || S.step;
    if (!run) return;
    const text = run.start ? core.trajectory_csv(run.start.theta_o, run.start.dtheta_o, run.start.flight, run.t_end, run.dt)
      : core.step_csv(run.dt);
    if (text.startsWith("{")) return showError(JSON.parse(text));
    download("trajectory.csv", new Blob([text], { type: "text/csv" }));
  };
  S.caseFileName = () => (S.caseName || "case").replace(/\W+/g, "_") + ".toml";
  $("dl_case").onclick = () => S.loaded && download(S.caseFileName(), new Blob([S.loaded.case_file], { type: "application/toml" }));

  /// A measured record (the project's CSV, docs/design.md "Measured data (CSV)": a header naming
  /// the columns, t and theta_out required, t strictly increasing, every cell a finite number,
  /// at least 10 rows) overlaid on the time panel and, with its differences, on the phase plane.
  /// Reading a table is no physics.  A bad record: the first problem, "FILE:LINE: COLUMN:
  /// problem", beside the drop zone; the picture is kept.
  function recordProblem(text, name) {
    const lines = text.replace(/^\uFEFF/, "").split(/\r?\n/);
    while (lines.length && lines[lines.length - 1].trim() === "") lines.pop();
    const header = (lines[0] ?? "").split(",").map((x) => x.trim());
    for (const c of ["t", "theta_out"]) if (!header.includes(c)) return { message: `${name}:1: ${c}: missing column (the header is "${lines[0] ?? ""}")` };
    const it = header.indexOf("t"), io = header.indexOf("theta_out"), t = [], theta = [];
    for (let k = 1; k < lines.length; k++) {
      const cells = lines[k].split(",");
      if (cells.length !== header.length) return { message: `${name}:${k + 1}: the row has ${cells.length} cells, the header ${header.length}` };
      for (const [i, col] of [[it, "t"], [io, "theta_out"]]) {
        const cell = cells[i].trim();
        if (!/^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/.test(cell) || !Number.isFinite(Number(cell)))
          return { message: `${name}:${k + 1}: ${col}: not a finite number: "${cell}"` };
      }
      const a = Number(cells[it]), b = Number(cells[io]);
      if (t.length && !(a > t[t.length - 1])) return { message: `${name}:${k + 1}: t: time ${a} is not after ${t[t.length - 1]}; t must be strictly increasing` };
      t.push(a); theta.push(b);
    }
    if (t.length < 10) return { message: `${name}: too few samples: ${t.length} data rows, at least 10 required` };
    return { t, theta };
  }
  function loadRecord(text, name) {
    const r = recordProblem(text, name);
    $("e_record").textContent = r.message || "";
    if (r.message) return setStatus(r.message + "\n(the last valid picture is kept)", true);
    const { t, theta } = r;
    const dtheta = theta.slice(0, -1).map((x, i) => (theta[i + 1] - x) / (t[i + 1] - t[i]));
    S.record = { name, t, theta, dtheta, thetaForPlane: theta.slice(0, -1) };
    draw();
    setStatus(`record ${name}: ${t.length} samples overlaid`, false);
  }
  S.loadRecord = loadRecord;
  const readRecordFile = (f) => f && f.text().then((text) => loadRecord(text, f.name));
  document.body.addEventListener("dragover", (ev) => ev.preventDefault());
  document.body.addEventListener("drop", (ev) => { ev.preventDefault(); readRecordFile(ev.dataTransfer.files[0]); });
  $("record_file").addEventListener("change", () => readRecordFile($("record_file").files[0]));
  window.addEventListener("resize", () => S.loaded && draw());

  $("case").value = "V";
  showCase("V");
  S.ready = true;
})();
