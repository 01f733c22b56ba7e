// partlab box editor: a Streamlit components-v2 component (plain JS, no build).
//
// The browser keeps a frame cache: Python sends JPEG frames and the boxes of frames in
// chunks the editor asks for (the state value "view": {frame, lo, hi, blo, bhi, req}),
// around the shown frame and ahead of it while playing, so stepping and playing never wait
// for a Streamlit rerun. Python's data: {width, height, frame_count, fps, parts, tracks,
// next_track_id, mode, applied_seq, version, jump: {seq, frame}, chunk: {req, lo, frames,
// blo, bhi, boxes: {frame: [[track, part index, x, y, w, h, flags, occluded, revision]]}},
// timeline: {tracks: [{id, colour, spans, keys, fails, acc, rej}], flagged, events: [{id, revision,
// start, end, type, colour}], kinds}}; flags: 1
// failure, 2 human (a keyframe). `version` changes whenever stored boxes change; cached
// boxes of another version are asked for again. Every user action becomes an event {seq,
// kind, ...} sent as the trigger value "events" until Python reports it applied
// (applied_seq). Text from the user or the data is only ever set through textContent.

const SVG_NS = "http://www.w3.org/2000/svg";
const HANDLE_PX = 5;   // handle half-size in screen pixels, whatever the zoom
const GRAB_PX = 9;     // grab distance of a handle in screen pixels
const MIN_SIZE = 2;    // smallest box side in image pixels
const BEHIND = 10, AHEAD = 40, PLAY_AHEAD = 80, CHUNK = 24, BOX_WINDOW = 120;
const DECODE_BEHIND = 15, DECODE_AHEAD = 60; // decoded frames kept: 75 x 1.7 MB at 768x576
const INSTANCES = new WeakMap();
const SHORT = { hipleg: "hip-leg", left_hand: "L hand", right_hand: "R hand" };

function el(name, attrs) {
  const node = document.createElementNS(SVG_NS, name);
  for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, String(v));
  return node;
}
function keyOf(b) { return b.track_id + ":" + b.part; }
function isOccluded(b) { return Number(b.occluded || 0) >= 0.5; }

class Editor {
  constructor(root) {
    const q = (s) => root.querySelector(s);
    this.root = q(".pl-editor");
    this.viewport = q(".pl-viewport");
    this.stage = q(".pl-stage");
    this.canvas = q(".pl-image");
    this.svg = q(".pl-overlay");
    this.loading = q(".pl-loading");
    this.frameLabel = q(".pl-frame");
    this.zoomLabel = q(".pl-zoom");
    this.status = q(".pl-status");
    this.addPart = q(".pl-add-part");
    this.addTrack = q(".pl-add-track");
    this.speed = q(".pl-speed");
    this.timeline = q(".pl-timeline");
    this.partsBox = q(".pl-parts");
    this.tracksBox = q(".pl-tracks");
    this.eventType = q(".pl-event-type");
    this.eventInfo = q(".pl-event-info");
    this.events = [];          // the clip's events on the timeline: {id, revision, start, end, type, colour}
    this.selEvent = null;      // the id of the selected event
    this.evDrag = null;        // {ev, edge, orig: [start, end]} while an end of an event is dragged
    this.data = null;
    this.frames = new Map();   // frame -> decoded image (ImageBitmap or HTMLImageElement)
    this.boxes = new Map();    // frame -> box list of `this.version`
    this.version = null;
    this.cur = 0;              // the frame shown
    this.shown = [];           // its boxes (the same objects as in this.boxes)
    this.selected = null;
    this.hover = null;
    this.hiddenTracks = new Set();
    this.hiddenParts = new Set();
    this.labelsAll = false;
    this.drawMode = false;
    this.fill = true;
    this.pending = [];
    this.seq = 0;
    this.req = 0;
    this.inflight = null;      // {req, lo, hi, blo, bhi, t}
    this.jumpSeq = null;
    this.drag = null;
    this.pan = null;
    this.zoom = 1; this.ox = 0; this.oy = 0; this.fitted = false;
    this.playing = false;
    this.stats = { steps: [], shown: [], played: 0, playStart: 0, playMs: 0, stalls: 0, keyAt: null, ready: -1 };
    this.setTrigger = null;
    this.setState = null;
    this.syncTimer = null;
    this.bind();
  }

  // ------------------------------------------------------------ data in
  update(data) {
    const first = this.data === null;
    this.data = data || {};
    const d = this.data;
    const applied = Number(d.applied_seq || 0);
    this.seq = Math.max(this.seq, applied);
    this.pending = this.pending.filter((e) => e.seq > applied);
    if (d.version !== this.version) { this.version = d.version; this.boxes.clear(); }
    this.merge(d.chunk);
    const partNames = d.parts || [];
    this.fillSelect(this.addPart, partNames.map((p) => [p, p]), this.addPart.value);
    const tracks = (d.tracks || []).map((t) => [String(t.id), "#" + t.id]);
    tracks.push(["new", `new #${d.next_track_id}`]);
    this.fillSelect(this.addTrack, tracks, this.addTrack.value || "new");
    const fps = Math.round(d.fps || 10);
    const speeds = [...new Set([fps, 15, 25, 30])].sort((a, b) => a - b).map((v) => [String(v), `${v} fps`]);
    this.fillSelect(this.speed, speeds, this.speed.value || String(fps));
    const occl = d.mode === "occluders";
    for (const sel of [".pl-add", ".pl-legend", ".pl-timeline", ".pl-eventbar"]) this.root.querySelector(sel).style.display = occl ? "none" : "";
    for (const act of ["track", "failure", "occluded", "undo", "redo", "flag", "keyframe", "fill", "labels"]) {
      this.root.querySelector(`[data-act="${act}"]`).style.display = occl ? "none" : "";
    }
    this.legend();
    this.takeEvents();
    if (first) {
      this.setStatus(occl ? "draw occluder regions; drag to move, Delete removes" :
        "click a box to select it; drag to move, corners to resize; B or Shift+drag draws a new box; wheel zooms, right-drag pans");
      this.layout();
    }
    const jump = d.jump || { seq: 0, frame: 0 };
    if (jump.seq !== this.jumpSeq) { this.jumpSeq = jump.seq; this.show(jump.frame, false); }
    else this.show(this.cur, false);
    this.buttons();
  }

  merge(chunk) {
    if (!chunk) return;
    if (this.inflight && chunk.req >= this.inflight.req) this.inflight = null;
    (chunk.frames || []).forEach((url, i) => {
      const f = chunk.lo + i;
      if (url && !this.frames.has(f)) this.frames.set(f, { url, bmp: null, decoding: false });
    });
    this.decodeAround();
    if (chunk.version === this.version) {
      for (const [f, rows] of Object.entries(chunk.boxes || {})) {
        if (!this.boxes.has(Number(f)) || !this.dirty(Number(f))) this.boxes.set(Number(f), rows.map((r) => this.unpack(r)));
      }
      for (let f = chunk.blo; f < chunk.bhi; f++) if (!this.boxes.has(f)) this.boxes.set(f, []);
    }
    // JPEGs are kept for 1500 frames (about 150 MB at 768x576), the farthest go first
    if (this.frames.size > 1500) {
      const far = [...this.frames.keys()].sort((a, b) => Math.abs(b - this.cur) - Math.abs(a - this.cur));
      for (const f of far.slice(0, this.frames.size - 1200)) { const e = this.frames.get(f); if (e.bmp) e.bmp.close(); this.frames.delete(f); }
    }
  }

  // decoded bitmaps (drawn in a millisecond; decoding a JPEG on the main thread costs far more)
  // are kept for the frames near the shown one and decoded off the main thread
  decodeAround() {
    const lo = this.cur - DECODE_BEHIND, hi = this.cur + DECODE_AHEAD;
    for (const [f, e] of this.frames) {
      if ((f < lo || f >= hi) && e.bmp) { e.bmp.close(); e.bmp = null; }
    }
    let started = 0;
    for (let f = this.cur; f < hi && started < 8; f++) started += this.decode(f);
    for (let f = this.cur - 1; f >= lo && started < 8; f--) started += this.decode(f);
  }

  decode(f) {
    const e = this.frames.get(f);
    if (!e || e.bmp || e.decoding) return 0;
    e.decoding = true;
    fetch(e.url).then((r) => r.blob()).then((b) => createImageBitmap(b)).then((bmp) => {
      e.decoding = false;
      if (this.frames.get(f) !== e || f < this.cur - DECODE_BEHIND || f >= this.cur + DECODE_AHEAD) { bmp.close(); return; }
      e.bmp = bmp;
      if (f === this.cur) this.draw();
      this.decodeAround();
    }, () => { e.decoding = false; });
    return 1;
  }

  ready(f) { const e = this.frames.get(f); return !!(e && e.bmp); }

  dirty(f) { return this.pending.some((e) => e.frame === f && (e.kind === "edit" || e.kind === "delete")); }

  unpack(r) {
    const parts = this.data.parts || [];
    const colour = (this.data.colours || {})[r[0]] || "#4e79a7";
    return { track_id: r[0], part: parts[r[1]] || String(r[1]), x: r[2], y: r[3], w: r[4], h: r[5],
      failure: !!(r[6] & 1), human: !!(r[6] & 2), occluded: r[7], revision: r[8], colour };
  }

  fillSelect(select, options, keep) {
    const sig = JSON.stringify(options);
    if (select.dataset.sig !== sig) {
      while (select.firstChild) select.removeChild(select.firstChild);
      for (const [value, text] of options) {
        const o = document.createElement("option");
        o.value = value;
        o.textContent = text;
        select.appendChild(o);
      }
      select.dataset.sig = sig;
    }
    if (keep && options.some(([v]) => v === keep)) select.value = keep;
  }

  // ------------------------------------------------------------ the frame cache
  show(f, user) {
    const last = Math.max(0, (this.data.frame_count || 1) - 1);
    f = Math.min(Math.max(Number(f) || 0, 0), last);
    const changed = f !== this.cur;
    this.cur = f;
    if (changed && this.selected) {
      // keep the selection on the same track and part when it exists in the new frame
      const still = (this.boxes.get(f) || []).some((b) => keyOf(b) === this.selected);
      if (!still) this.selected = null;
    }
    if (changed) this.drawn = null;
    this.draw();
    this.decodeAround();
    this.ensure();
    if (user) this.scheduleSync();
  }

  draw() {
    if (!this.data) return;
    const ready = this.ready(this.cur);
    if (ready && this.drawn !== this.cur) {
      this.canvas.getContext("2d").drawImage(this.frames.get(this.cur).bmp, 0, 0, this.canvas.width, this.canvas.height);
      this.drawn = this.cur;
    }
    this.shown = this.boxes.get(this.cur) || [];
    const haveBoxes = this.boxes.has(this.cur) || this.data.mode === "occluders";
    if (this.data.mode === "occluders") this.shown = this.occluderBoxes();
    this.loading.textContent = ready ? (haveBoxes ? "" : "loading boxes...") : `loading frame ${this.cur}...`;
    this.stats.ready = ready && haveBoxes ? this.cur : -1;
    this.showFrameLabel();
    this.render();
    this.drawTimeline();
    if (ready && haveBoxes && this.stats.keyAt) {
      // key press to the frame on screen: measured at the animation frame after the one that paints it
      const t0 = this.stats.keyAt, f = this.cur;
      this.stats.keyAt = null;
      requestAnimationFrame(() => requestAnimationFrame(() => {
        const ms = performance.now() - t0;
        this.stats.shown.push([f, ms]);
      }));
    }
  }

  occluderBoxes() {
    if (!this.occl) this.occl = (this.data.occluders || []).map((b, i) => ({ ...b, track_id: i, part: "occluder" }));
    return this.occl;
  }

  // which frames and boxes to ask Python for next
  ensure() {
    if (!this.data || !this.setState) return;
    const n = this.data.frame_count || 0;
    const ahead = this.playing ? PLAY_AHEAD : AHEAD;
    const lo = Math.max(0, this.cur - BEHIND), hi = Math.min(n, this.cur + ahead);
    let first = -1;
    for (let f = this.cur; f < hi && first < 0; f++) if (!this.frames.has(f)) first = f;
    for (let f = this.cur - 1; f >= lo && first < 0; f--) if (!this.frames.has(f)) first = f;
    let bfirst = -1;
    for (let f = this.cur; f < hi && bfirst < 0; f++) if (!this.boxes.has(f)) bfirst = f;
    for (let f = this.cur - 1; f >= lo && bfirst < 0; f--) if (!this.boxes.has(f)) bfirst = f;
    if (first < 0 && bfirst < 0) return;
    const now = performance.now();
    if (this.inflight && now - this.inflight.t < 2500) {
      const i = this.inflight;
      const coveredF = first < 0 || (first >= i.lo && first < i.hi);
      const coveredB = bfirst < 0 || (bfirst >= i.blo && bfirst < i.bhi);
      if (coveredF && coveredB) return;
    }
    let flo = 0, fhi = 0;
    if (first >= 0) {
      flo = first;
      fhi = flo;
      while (fhi < n && fhi - flo < CHUNK && !this.frames.has(fhi)) fhi++;
    }
    let blo = 0, bhi = 0;
    if (bfirst >= 0) { blo = Math.max(0, Math.min(bfirst, this.cur - BEHIND)); bhi = Math.min(n, blo + BOX_WINDOW); }
    this.inflight = { req: ++this.req, lo: flo, hi: fhi, blo, bhi, t: now };
    this.sentFrame = this.cur; // the frame Python was last told of (the browser test waits on it)
    this.setState("view", { frame: this.cur, lo: flo, hi: fhi, blo, bhi, req: this.req });
  }

  scheduleSync() {
    // Python learns the shown frame once stepping pauses (no rerun per step)
    clearTimeout(this.syncTimer);
    this.syncTimer = setTimeout(() => {
      if (this.playing || !this.setState) return;
      const i = this.inflight || { lo: 0, hi: 0, blo: 0, bhi: 0 };
      this.sentFrame = this.cur;
      this.setState("view", { frame: this.cur, lo: i.lo, hi: i.hi, blo: i.blo, bhi: i.bhi, req: this.inflight ? this.inflight.req : this.req });
    }, 400);
  }

  step(delta, user = true) {
    const t0 = performance.now();
    this.show(this.cur + delta, user);
    this.stats.steps.push(performance.now() - t0);
  }

  // ------------------------------------------------------------ play
  togglePlay() {
    this.playing = !this.playing;
    this.buttons();
    if (!this.playing) { this.scheduleSync(); return; }
    if (this.cur >= (this.data.frame_count || 1) - 1) this.show(0, false); // play at the end starts over
    const fps = Number(this.speed.value) || this.data.fps || 10;
    const interval = 1000 / fps;
    let next = performance.now() + interval;
    this.stats.played = 0; this.stats.stalls = 0; this.stats.playStart = performance.now();
    const tick = (now) => {
      if (!this.playing) return;
      if (now >= next - 1) {
        const last = (this.data.frame_count || 1) - 1;
        if (this.cur >= last) { this.playing = false; this.buttons(); this.scheduleSync(); return; }
        if (this.ready(this.cur + 1) && this.boxes.has(this.cur + 1)) {
          this.show(this.cur + 1, false);
          this.stats.played++;
          this.stats.playMs = performance.now() - this.stats.playStart;
          next = Math.max(next + interval, now - interval);
        } else { this.stats.stalls++; this.ensure(); }
      }
      requestAnimationFrame(tick);
    };
    this.ensure();
    requestAnimationFrame(tick);
  }

  // ------------------------------------------------------------ zoom and pan
  layout() {
    const W = this.data.width || 1, H = this.data.height || 1;
    if (this.canvas.width !== W || this.canvas.height !== H) { this.canvas.width = W; this.canvas.height = H; this.drawn = null; }
    this.svg.setAttribute("viewBox", `0 0 ${W} ${H}`);
    const cw = Math.max(200, this.viewport.clientWidth || this.root.clientWidth - 160);
    // the whole frame above the fold: the viewport ends ~110 px (timeline, status) above the window's bottom
    const top = this.viewport.getBoundingClientRect().top + window.scrollY;
    const room = Math.max(220, window.innerHeight - top - 110);
    const vh = Math.min(room, (cw * H) / W);
    this.viewport.style.height = `${Math.round(vh)}px`;
    this.vw = cw; this.vh = vh;
    if (!this.fitted) this.fit();
    this.applyView();
  }

  fit() {
    const W = this.data.width || 1, H = this.data.height || 1;
    this.zoom = Math.min(this.vw / W, this.vh / H);
    this.ox = (this.vw - W * this.zoom) / 2; this.oy = (this.vh - H * this.zoom) / 2;
    this.fitted = true;
    this.applyView();
  }

  zoomAt(factor, sx, sy) {
    const z = Math.min(Math.max(this.zoom * factor, 0.1), 32);
    // keep the image point under (sx, sy) where it is
    const ix = (sx - this.ox) / this.zoom, iy = (sy - this.oy) / this.zoom;
    this.zoom = z;
    this.ox = sx - ix * z; this.oy = sy - iy * z;
    this.applyView();
  }

  applyView() {
    const W = this.data.width || 1, H = this.data.height || 1;
    this.stage.style.width = `${W * this.zoom}px`;
    this.stage.style.height = `${H * this.zoom}px`;
    this.stage.style.transform = `translate(${this.ox}px, ${this.oy}px)`;
    this.zoomLabel.textContent = `${(this.zoom * 100).toFixed(0)}%`;
    this.render();
  }

  // ------------------------------------------------------------ drawing
  visible(b) { return !this.hiddenTracks.has(b.track_id) && !this.hiddenParts.has(b.part); }

  render() {
    if (!this.data) return;
    const svg = this.svg;
    while (svg.firstChild) svg.removeChild(svg.firstChild);
    const u = 1 / this.zoom; // image pixels per screen pixel
    const font = 11 * u;
    const occl = this.data.mode === "occluders";
    let sel = null;
    for (const b of this.shown) {
      if (!occl && !this.visible(b)) continue;
      const isSel = keyOf(b) === this.selected;
      if (isSel) sel = b;
      const cls = occl ? "pl-occluder" : ["pl-box", b.failure ? "pl-failure" : "", isOccluded(b) ? "pl-occluded" : "",
        b.human ? "pl-keyframe" : "", isSel ? "pl-selected" : ""].join(" ");
      const rect = el("rect", { x: b.x, y: b.y, width: b.w, height: b.h, class: cls,
        "data-track": b.track_id, "data-part": b.part });
      if (!occl) { rect.setAttribute("stroke", b.colour); rect.setAttribute("fill", b.colour); }
      if (isSel && occl) rect.setAttribute("stroke", "#ff0");
      svg.appendChild(rect);
    }
    if (!occl) {
      // labels: on every box with "labels: all", else on the hovered and the selected box only, above the box
      for (const b of this.shown) {
        if (!this.visible(b)) continue;
        const k = keyOf(b);
        if (!this.labelsAll && k !== this.selected && k !== this.hover) continue;
        const flags = `${b.failure ? " FAIL" : ""}${isOccluded(b) ? " occl" : ""}${b.human ? " key" : ""}`;
        const label = el("text", { x: b.x, y: Math.max(font, b.y - 2 * u), class: "pl-label", "font-size": font,
          "stroke-width": font * 0.2, "data-label": k });
        label.textContent = `#${b.track_id} ${SHORT[b.part] || b.part}${flags}`;
        svg.appendChild(label);
      }
    }
    if (sel) this.drawHandles(sel);
  }

  drawHandles(b) {
    const s = HANDLE_PX / this.zoom;
    for (const [name, x, y] of this.corners(b)) {
      this.svg.appendChild(el("rect", { x: x - s, y: y - s, width: 2 * s, height: 2 * s, class: `pl-handle pl-${name}`,
        "data-handle": name }));
    }
  }

  corners(b) {
    return [["nw", b.x, b.y], ["ne", b.x + b.w, b.y], ["sw", b.x, b.y + b.h], ["se", b.x + b.w, b.y + b.h]];
  }

  legend() {
    const d = this.data;
    const sig = JSON.stringify([(d.tracks || []).map((t) => t.id), d.parts]);
    if (this.legendSig === sig) return;
    this.legendSig = sig;
    const row = (box, text, colour, checked, onChange, attr) => {
      const label = document.createElement("label");
      const cb = document.createElement("input");
      cb.type = "checkbox"; cb.checked = checked;
      cb.setAttribute(attr[0], attr[1]);
      cb.addEventListener("change", () => { onChange(cb.checked); this.tlSig = null; this.render(); this.drawTimeline(); });
      label.appendChild(cb);
      if (colour) { const sw = document.createElement("span"); sw.className = "pl-swatch"; sw.style.background = colour; label.appendChild(sw); }
      const t = document.createElement("span"); t.textContent = text; label.appendChild(t);
      box.appendChild(label);
    };
    for (const box of [this.partsBox, this.tracksBox]) while (box.firstChild) box.removeChild(box.firstChild);
    for (const p of (d.parts || []).filter((p) => (d.used_parts || d.parts).includes(p))) {
      row(this.partsBox, SHORT[p] || p, null, !this.hiddenParts.has(p),
        (on) => (on ? this.hiddenParts.delete(p) : this.hiddenParts.add(p)), ["data-part-toggle", p]);
    }
    for (const t of d.tracks || []) {
      row(this.tracksBox, `#${t.id}${t.state ? " " + t.state : ""}`, t.colour, !this.hiddenTracks.has(t.id),
        (on) => (on ? this.hiddenTracks.delete(t.id) : this.hiddenTracks.add(t.id)), ["data-track-toggle", String(t.id)]);
    }
  }

  drawTimeline() {
    // the tracks' rows are drawn once per data / visibility change into a layer; a frame step only
    // copies the layer and draws the cursor
    const tl = (this.data.timeline || {});
    const tracks = (tl.tracks || []).filter((t) => !this.hiddenTracks.has(t.id));
    const c = this.timeline;
    const rowH = 7, top = 10, labelW = 34;
    const lanes = this.eventLanes();
    const evTop = top + Math.max(1, tracks.length) * rowH + 3, laneH = 8;
    const h = evTop + Math.max(1, lanes.count) * laneH + 2;
    const w = Math.max(100, c.clientWidth || 600);
    const n = Math.max(1, this.data.frame_count || 1);
    const X = (f) => labelW + (f / n) * (w - labelW);
    const sig = `${w}:${h}:${this.version}:${[...this.hiddenTracks].join(",")}:${JSON.stringify(tl.flagged || []).length}:` +
      `${JSON.stringify(this.events)}:${this.selEvent}`;
    if (this.tlSig !== sig) {
      this.tlSig = sig;
      if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
      const layer = this.tlLayer || (this.tlLayer = document.createElement("canvas"));
      layer.width = w; layer.height = h;
      const ctx = layer.getContext("2d");
      ctx.clearRect(0, 0, w, h);
      ctx.fillStyle = "#e15759"; // flagged frames on the top strip
      for (const f of tl.flagged || []) ctx.fillRect(X(f), 0, Math.max(1, (w - labelW) / n), 4);
      ctx.font = "9px sans-serif";
      tracks.forEach((t, i) => {
        const y = top + i * rowH;
        ctx.fillStyle = "#888"; ctx.fillText(`#${t.id}`, 0, y + rowH - 1);
        ctx.globalAlpha = 0.75; ctx.fillStyle = t.colour;
        for (const [a, b] of t.spans || []) ctx.fillRect(X(a), y + 1, Math.max(1, X(b + 1) - X(a)), rowH - 2);
        ctx.globalAlpha = 1;
        ctx.fillStyle = "#2ca02c"; for (const [a, b] of t.acc || []) ctx.fillRect(X(a), y + rowH - 2, X(b + 1) - X(a), 2);
        ctx.fillStyle = "#d62728"; for (const [a, b] of t.rej || []) ctx.fillRect(X(a), y + rowH - 2, X(b + 1) - X(a), 2);
        ctx.fillStyle = "#000"; for (const f of t.fails || []) ctx.fillRect(X(f), y + 1, 1, rowH - 2);
        ctx.fillStyle = "#fff"; for (const f of t.keys || []) ctx.fillRect(X(f) - 1, y, 2, rowH);
      });
      ctx.fillStyle = "#888"; ctx.fillText("events", 0, evTop + laneH - 1);
      for (const e of this.events) {  // each event a coloured range in its lane; the selected one outlined
        const y = evTop + lanes.of.get(e) * laneH;
        ctx.fillStyle = e.colour || "#bab0ac";
        ctx.fillRect(X(e.start), y + 1, Math.max(2, X(e.end + 1) - X(e.start)), laneH - 2);
        if (e.id === this.selEvent) {
          ctx.strokeStyle = "#000"; ctx.lineWidth = 2;
          ctx.strokeRect(X(e.start), y + 1, Math.max(2, X(e.end + 1) - X(e.start)), laneH - 2);
        }
      }
    }
    const ctx = c.getContext("2d");
    ctx.clearRect(0, 0, c.width, c.height);
    ctx.drawImage(this.tlLayer, 0, 0);
    ctx.fillStyle = "#ff4b4b";
    ctx.fillRect(X(this.cur) - 1, 0, 2, h);
    this.tlGeom = { labelW, w, n, top, rowH, tracks, evTop, laneH, lanes, X };
  }

  // ------------------------------------------------------------ events on the timeline
  takeEvents() {
    if (this.evDrag) return; // the user is stretching one: keep the local copy until the drop
    const kinds = (this.data.timeline || {}).kinds || ["clap", "handshake", "exchange", "pick", "place"];
    this.fillSelect(this.eventType, kinds.map((k) => [k, k]), this.eventType.value || kinds[0]);
    this.events = ((this.data.timeline || {}).events || []).map((e) => ({ ...e }));
    if (!this.events.some((e) => e.id === this.selEvent)) this.selEvent = null;
    this.eventStatus();
  }

  eventLanes() {
    // overlapping events go to separate lanes (first lane free at the event's start)
    const ends = [], of = new Map();
    for (const e of [...this.events].sort((a, b) => a.start - b.start)) {
      let lane = ends.findIndex((end) => end < e.start);
      if (lane < 0) { lane = ends.length; ends.push(e.end); } else ends[lane] = e.end;
      of.set(e, lane);
    }
    return { count: ends.length, of };
  }

  selectedEvent() { return this.events.find((e) => e.id === this.selEvent) || null; }

  eventStatus() {
    const e = this.selectedEvent();
    this.eventInfo.textContent = e ? `#${e.id} ${e.type} ${e.start}-${e.end}` : `${this.events.length} events`;
  }

  redrawEvents() { this.tlSig = null; this.drawTimeline(); this.eventStatus(); }

  eventAt(ev) {
    // the event under the pointer on the timeline's event row and which of its ends is within 5 px
    const g = this.tlGeom;
    if (!g) return null;
    const r = this.timeline.getBoundingClientRect();
    const x = ev.clientX - r.left, y = ev.clientY - r.top;
    if (y < g.evTop) return null;
    const lane = Math.floor((y - g.evTop) / g.laneH);
    const frame = Math.round(((x - g.labelW) / (g.w - g.labelW)) * g.n);
    const hits = this.events.filter((e) => g.lanes.of.get(e) === lane && x >= g.X(e.start) - 5 && x <= g.X(e.end + 1) + 5);
    const e = hits[0];
    if (!e) return { e: null, frame };
    const edge = Math.abs(x - g.X(e.end + 1)) <= 5 ? "end" : Math.abs(x - g.X(e.start)) <= 5 ? "start" : null;
    return { e, edge, frame };
  }

  frameAtX(clientX) {
    const g = this.tlGeom, r = this.timeline.getBoundingClientRect();
    const f = Math.floor(((clientX - r.left - g.labelW) / (g.w - g.labelW)) * g.n);
    return Math.min(Math.max(f, 0), g.n - 1);
  }

  onTimelineDown(ev) {
    const hit = this.eventAt(ev);
    if (!hit) return;
    this.tlSkipClick = true; // the event row is not a jump-to-frame click
    ev.preventDefault();
    if (!hit.e) { this.selEvent = null; this.redrawEvents(); return; }
    this.selEvent = hit.e.id;
    this.eventType.value = hit.e.type;
    if (hit.edge) {
      this.evDrag = { ev: hit.e, edge: hit.edge, orig: [hit.e.start, hit.e.end] };
      this.timeline.setPointerCapture(ev.pointerId);
    } else this.show(hit.e.start, true); // a click on an event jumps to its start
    this.setStatus(`${hit.e.type} event ${hit.e.start}-${hit.e.end}` + (hit.edge ? ": drag to stretch" : ""));
    this.redrawEvents();
  }

  onTimelineMove(ev) {
    const d = this.evDrag;
    if (!d) {
      const hit = this.eventAt(ev);
      this.timeline.style.cursor = hit && hit.edge ? "ew-resize" : "pointer";
      return;
    }
    const f = this.frameAtX(ev.clientX);
    if (d.edge === "end") d.ev.end = Math.max(d.ev.start, f);
    else d.ev.start = Math.min(d.ev.end, f);
    this.redrawEvents();
  }

  onTimelineUp(ev) {
    const d = this.evDrag;
    if (!d) return;
    this.evDrag = null;
    try { this.timeline.releasePointerCapture(ev.pointerId); } catch (e) { /* already released */ }
    const e = d.ev;
    if (e.start === d.orig[0] && e.end === d.orig[1]) return;
    if (e.id === null) { [e.start, e.end] = d.orig; this.redrawEvents(); return this.setStatus("the new event is being saved; try again"); }
    this.emit({ kind: "event_edit", event_id: e.id, revision: e.revision, start_frame: e.start, end_frame: e.end });
    e.revision += 1;
    this.setStatus(`${e.type} event now ${e.start}-${e.end}`);
    this.redrawEvents();
  }

  addEvent() {
    const type = this.eventType.value;
    const last = Math.max(0, (this.data.frame_count || 1) - 1);
    const end = Math.min(last, this.cur + Math.max(1, Math.round(this.data.fps || 10)) - 1);
    this.emit({ kind: "event_add", type, start_frame: this.cur, end_frame: end });
    this.events.push({ id: null, revision: 1, start: this.cur, end, type, colour: "#888" }); // until Python's answer
    this.setStatus(`added a ${type} event ${this.cur}-${end}; drag its ends on the event row to stretch it`);
    this.redrawEvents();
  }

  eventAct(name, shift) {
    const e = this.selectedEvent();
    if (name === "event_add") return this.addEvent();
    if (name === "event_next") {
      const starts = [...new Set(this.events.map((x) => x.start))].sort((a, b) => a - b);
      return this.jumpTo(starts, shift, "event");
    }
    if (!e || e.id === null) return this.setStatus("select an event first (click it on the timeline's event row)");
    this.emit({ kind: "event_delete", event_id: e.id, revision: e.revision });
    this.events.splice(this.events.indexOf(e), 1);
    this.selEvent = null;
    this.setStatus(`deleted the ${e.type} event ${e.start}-${e.end}`);
    this.redrawEvents();
  }

  retypeEvent() {
    const e = this.selectedEvent();
    if (!e || e.id === null || e.type === this.eventType.value) return;
    e.type = this.eventType.value;
    this.emit({ kind: "event_edit", event_id: e.id, revision: e.revision, type: e.type });
    e.revision += 1;
    this.setStatus(`event #${e.id} is now a ${e.type}`);
    this.redrawEvents();
  }

  setStatus(text) { this.status.textContent = text; }

  showFrameLabel() {
    const last = Math.max(0, (this.data.frame_count || 1) - 1);
    this.frameLabel.textContent = `frame ${this.cur} / ${last}`;
  }

  buttons() {
    const on = (act, v) => this.root.querySelector(`[data-act="${act}"]`).classList.toggle("pl-on", !!v);
    on("play", this.playing); on("draw", this.drawMode); on("fill", this.fill);
    this.root.querySelector('[data-act="play"]').textContent = this.playing ? "pause" : "play";
    this.root.querySelector('[data-act="labels"]').textContent = this.labelsAll ? "labels: all" : "labels: hover";
    this.root.classList.toggle("pl-drawing", this.drawMode);
  }

  // ------------------------------------------------------------ events out
  emit(event) {
    event.seq = ++this.seq;
    if (event.frame === undefined) event.frame = this.cur;
    this.pending.push(event);
    if (this.setTrigger) this.setTrigger("events", this.pending.slice());
  }

  emitBox(b, extra) {
    this.emit({ kind: "edit", track_id: b.track_id, part: b.part, box: [b.x, b.y, b.w, b.h],
      failure: !!b.failure, occluded: Number(b.occluded || 0), revision: b.revision ?? null, based_on: b.basedOn || 0,
      fill: this.fill, ...extra });
    b.revision = (b.revision ?? 0) + 1; // optimistic: the next edit of this box expects our revision
    b.basedOn = this.seq; // ... which holds only if that edit is saved: Python refuses the next one otherwise
    b.human = true;
  }

  emitOccluders() {
    this.emit({ kind: "occluders", boxes: this.shown.map((b) => [b.x, b.y, b.w, b.h]) });
  }

  selectedBox() { return this.shown.find((b) => keyOf(b) === this.selected) || null; }

  // ------------------------------------------------------------ actions
  act(name, shift) {
    const occl = this.data.mode === "occluders";
    const b = this.selectedBox();
    if (name.startsWith("event_")) { if (!occl) this.eventAct(name, shift); }
    else if (name === "prev" || name === "next") this.step(name === "next" ? 1 : -1);
    else if (name === "play") this.togglePlay();
    else if (name === "track") this.nextTrack();
    else if (name === "undo" || name === "redo") { if (!occl) this.emit({ kind: name }); }
    else if (name === "fit") this.fit();
    else if (name === "one") this.zoomAt(1 / this.zoom, this.vw / 2, this.vh / 2);
    else if (name === "zoomin") this.zoomAt(1.5, this.vw / 2, this.vh / 2);
    else if (name === "zoomout") this.zoomAt(1 / 1.5, this.vw / 2, this.vh / 2);
    else if (name === "labels") { this.labelsAll = !this.labelsAll; this.buttons(); this.render(); }
    else if (name === "draw") { this.drawMode = !this.drawMode; this.buttons(); }
    else if (name === "fill") { this.fill = !this.fill; this.buttons(); this.setStatus(`track mode ${this.fill ? "on" : "off"}`); }
    else if (name === "flag") this.jumpTo((this.data.timeline || {}).flagged || [], shift, "flagged frame");
    else if (name === "keyframe") {
      const tid = b ? b.track_id : null;
      const t = ((this.data.timeline || {}).tracks || []).find((x) => x.id === tid);
      if (!t) return this.setStatus("select a box first: K goes to that track's next keyframe");
      this.jumpTo(t.keys || [], shift, `keyframe of #${tid}`);
    } else if (name === "delete") {
      if (!b) return this.setStatus("select a box first");
      const list = this.shown;
      list.splice(list.indexOf(b), 1);
      this.selected = null;
      if (occl) this.emitOccluders();
      else this.emit({ kind: "delete", track_id: b.track_id, part: b.part, revision: b.revision ?? null,
        based_on: b.basedOn || 0 });
      this.setStatus(`deleted ${b.part} of #${b.track_id}`);
      this.render();
    } else if ((name === "failure" || name === "occluded") && !occl) {
      if (!b) return this.setStatus("select a box first");
      if (name === "failure") b.failure = !b.failure;
      else b.occluded = isOccluded(b) ? 0 : 1;
      this.emitBox(b, { fill: false });
      const on = name === "failure" ? b.failure : isOccluded(b);
      this.setStatus(`#${b.track_id} ${b.part}: ${name} ${on ? "on" : "off"}`);
      this.render();
    }
  }

  jumpTo(frames, back, what) {
    const f = back ? [...frames].reverse().find((x) => x < this.cur) : frames.find((x) => x > this.cur);
    if (f === undefined) return this.setStatus(`no ${what} ${back ? "before" : "after"} this frame`);
    this.show(f, true);
    this.setStatus(`${what}: frame ${f}`);
  }

  nextTrack() {
    const list = this.shown.filter((b) => this.visible(b));
    if (!list.length) return;
    const order = list.slice().sort((a, b) => a.track_id - b.track_id || a.part.localeCompare(b.part));
    const cur = this.selectedBox();
    let next;
    if (!cur) next = order[0];
    else {
      const ids = [...new Set(order.map((b) => b.track_id))];
      const nextId = ids[(ids.indexOf(cur.track_id) + 1) % ids.length];
      next = order.find((b) => b.track_id === nextId && b.part === cur.part) || order.find((b) => b.track_id === nextId);
    }
    this.selected = keyOf(next);
    this.setStatus(`selected #${next.track_id} ${next.part}`);
    this.render();
  }

  // ------------------------------------------------------------ pointer
  point(ev) {
    const r = this.viewport.getBoundingClientRect();
    return [(ev.clientX - r.left - this.ox) / this.zoom, (ev.clientY - r.top - this.oy) / this.zoom];
  }

  hit(p) {
    const sel = this.selectedBox();
    const s = GRAB_PX / this.zoom;
    if (sel && this.visible(sel)) {
      for (const [name, x, y] of this.corners(sel)) {
        if (Math.abs(p[0] - x) <= s && Math.abs(p[1] - y) <= s) return { box: sel, handle: name };
      }
    }
    const inside = this.shown.filter((b) => this.visible(b) && p[0] >= b.x && p[0] <= b.x + b.w && p[1] >= b.y && p[1] <= b.y + b.h);
    inside.sort((a, b) => a.w * a.h - b.w * b.h); // the smallest box on top: parts inside the person
    return inside.length ? { box: inside[0], handle: null } : null;
  }

  onDown(ev) {
    this.root.focus({ preventScroll: true });
    if (ev.button === 1 || ev.button === 2 || (ev.button === 0 && this.spaceDown)) {
      this.pan = { x: ev.clientX, y: ev.clientY, ox: this.ox, oy: this.oy };
      this.svg.setPointerCapture(ev.pointerId);
      ev.preventDefault();
      return;
    }
    if (ev.button !== 0) return;
    const p = this.point(ev);
    const drawing = this.drawMode || ev.shiftKey;
    const h = drawing ? null : this.hit(p);
    if (h) {
      this.selected = keyOf(h.box);
      this.drag = { box: h.box, handle: h.handle, start: p, orig: { x: h.box.x, y: h.box.y, w: h.box.w, h: h.box.h } };
    } else {
      const occl = this.data.mode === "occluders";
      const part = occl ? "occluder" : this.addPart.value;
      const trackValue = this.addTrack.value;
      const track = occl ? this.shown.length : (trackValue === "new" ? this.data.next_track_id : Number(trackValue));
      if (!occl && this.shown.some((b) => b.track_id === track && b.part === part)) {
        this.selected = null;
        this.setStatus(`track #${track} already has a ${part} box here; choose another part or track`);
        this.render();
        return;
      }
      const colour = (this.data.colours || {})[track] || "#ffffff";
      const box = { track_id: track, part, x: p[0], y: p[1], w: 0, h: 0, failure: false, occluded: 0,
        revision: null, colour, human: true };
      this.drag = { box, handle: "se", start: p, orig: { x: p[0], y: p[1], w: 0, h: 0 }, isNew: true };
      this.selected = null;
    }
    this.svg.setPointerCapture(ev.pointerId);
    this.render();
    ev.preventDefault();
  }

  onMove(ev) {
    if (this.pan) {
      this.ox = this.pan.ox + ev.clientX - this.pan.x; this.oy = this.pan.oy + ev.clientY - this.pan.y;
      this.applyView();
      return;
    }
    const d = this.drag;
    if (!d) {
      const h = this.hit(this.point(ev));
      const k = h ? keyOf(h.box) : null;
      if (k !== this.hover) { this.hover = k; if (!this.labelsAll) this.render(); }
      return;
    }
    const p = this.point(ev);
    const dx = p[0] - d.start[0], dy = p[1] - d.start[1];
    const o = d.orig, b = d.box;
    const W = this.data.width || 1, H = this.data.height || 1;
    if (!d.handle) {
      b.x = Math.min(Math.max(o.x + dx, -o.w + 1), W - 1);
      b.y = Math.min(Math.max(o.y + dy, -o.h + 1), H - 1);
    } else {
      let x1 = o.x, y1 = o.y, x2 = o.x + o.w, y2 = o.y + o.h;
      if (d.handle.includes("w")) x1 += dx; else x2 += dx;
      if (d.handle.includes("n")) y1 += dy; else y2 += dy;
      b.x = Math.min(x1, x2); b.y = Math.min(y1, y2);
      b.w = Math.abs(x2 - x1); b.h = Math.abs(y2 - y1);
    }
    if (d.isNew && !this.shown.includes(b)) {
      if (!this.boxes.has(this.cur)) this.boxes.set(this.cur, this.shown);
      this.shown.push(b);
    }
    this.render();
  }

  onUp(ev) {
    if (this.pan) { this.pan = null; try { this.svg.releasePointerCapture(ev.pointerId); } catch (e) { /* */ } return; }
    const d = this.drag;
    this.drag = null;
    if (!d) return;
    try { this.svg.releasePointerCapture(ev.pointerId); } catch (e) { /* already released */ }
    const b = d.box, o = d.orig;
    const moved = Math.abs(b.x - o.x) + Math.abs(b.y - o.y) + Math.abs(b.w - o.w) + Math.abs(b.h - o.h) > 0.2;
    if (!moved) { this.render(); return; }
    for (const k of d.handle ? ["x", "y", "w", "h"] : ["x", "y"]) {
      if (b[k] !== o[k] || d.isNew) b[k] = Math.round(b[k] * 10) / 10;
    }
    if (d.isNew && (b.w < MIN_SIZE || b.h < MIN_SIZE)) {
      this.shown.splice(this.shown.indexOf(b), 1);
      this.render();
      return;
    }
    if (this.data.mode === "occluders") this.emitOccluders();
    else this.emitBox(b, d.isNew ? { added: true } : {});
    this.selected = keyOf(b);
    const what = this.data.mode === "occluders" ? "occluder region" : `${b.part} of #${b.track_id}`;
    this.setStatus(`${d.isNew ? "added" : "changed"} ${what}: x=${b.x} y=${b.y} w=${b.w} h=${b.h}`);
    this.render();
  }

  onWheel(ev) {
    ev.preventDefault();
    const r = this.viewport.getBoundingClientRect();
    this.zoomAt(ev.deltaY < 0 ? 1.25 : 1 / 1.25, ev.clientX - r.left, ev.clientY - r.top);
  }

  onTimeline(ev) {
    const g = this.tlGeom;
    if (this.tlSkipClick) { this.tlSkipClick = false; return; }
    if (!g) return;
    const r = this.timeline.getBoundingClientRect();
    const x = ev.clientX - r.left, y = ev.clientY - r.top;
    const f = Math.round(((x - g.labelW) / (g.w - g.labelW)) * g.n);
    this.show(f, true);
    const row = Math.floor((y - g.top) / g.rowH);
    const t = g.tracks[row];
    if (t) {
      const b = (this.boxes.get(this.cur) || []).find((x) => x.track_id === t.id);
      if (b) { this.selected = keyOf(b); this.render(); }
    }
  }

  onKey(ev) {
    if (ev.target && (ev.target.tagName === "SELECT" || ev.target.tagName === "INPUT")) return;
    const k = ev.key;
    const ctrl = ev.ctrlKey || ev.metaKey;
    let act = null;
    if (ctrl && (k === "z" || k === "Z")) act = ev.shiftKey ? "redo" : "undo";
    else if (ctrl && (k === "y" || k === "Y")) act = "redo";
    else if (ctrl || ev.altKey) return;
    else if (k === "ArrowRight" || k === "d" || k === "D") act = "next";
    else if (k === "ArrowLeft" || k === "a" || k === "A") act = "prev";
    else if (k === " ") act = "play";
    else if (k === "Tab" || k === "n" || k === "N") act = "track";
    else if (k === "f" || k === "F") act = "failure";
    else if (k === "o" || k === "O") act = "occluded";
    else if (k === "g" || k === "G") act = "flag";
    else if (k === "k" || k === "K") act = "keyframe";
    else if (k === "e" || k === "E") act = "event_add";
    else if (k === "j" || k === "J") act = "event_next";
    else if (k === "b" || k === "B") act = "draw";
    else if (k === "l" || k === "L") act = "labels";
    else if (k === "t" || k === "T") act = "fill";
    else if (k === "0") act = "fit";
    else if (k === "1") act = "one";
    else if (k === "+" || k === "=") act = "zoomin";
    else if (k === "-") act = "zoomout";
    else if (k === "Delete" || k === "Backspace") act = "delete";
    if (!act) return;
    ev.preventDefault();
    ev.stopPropagation();
    if (act === "next" || act === "prev") this.stats.keyAt = performance.now();
    this.act(act, ev.shiftKey);
  }

  bind() {
    this.svg.addEventListener("pointerdown", (ev) => this.onDown(ev));
    this.svg.addEventListener("pointermove", (ev) => this.onMove(ev));
    this.svg.addEventListener("pointerup", (ev) => this.onUp(ev));
    this.svg.addEventListener("pointercancel", (ev) => this.onUp(ev));
    this.svg.addEventListener("pointerleave", () => { if (this.hover && !this.drag) { this.hover = null; this.render(); } });
    this.svg.addEventListener("contextmenu", (ev) => ev.preventDefault());
    this.viewport.addEventListener("wheel", (ev) => this.onWheel(ev), { passive: false });
    this.timeline.addEventListener("click", (ev) => this.onTimeline(ev));
    this.timeline.addEventListener("pointerdown", (ev) => this.onTimelineDown(ev));
    this.timeline.addEventListener("pointermove", (ev) => this.onTimelineMove(ev));
    this.timeline.addEventListener("pointerup", (ev) => this.onTimelineUp(ev));
    this.timeline.addEventListener("pointercancel", (ev) => this.onTimelineUp(ev));
    this.eventType.addEventListener("change", () => this.retypeEvent());
    this.root.addEventListener("keydown", (ev) => { if (ev.key === " ") this.spaceDown = false; this.onKey(ev); });
    for (const button of this.root.querySelectorAll("button[data-act]")) {
      button.addEventListener("click", (ev) => { this.act(button.dataset.act, ev.shiftKey); this.root.focus({ preventScroll: true }); });
    }
    if (window.ResizeObserver) {
      let last = 0;
      new ResizeObserver(() => {
        const w = this.root.clientWidth;
        if (w !== last && this.data) { last = w; this.fitted = false; this.layout(); this.drawTimeline(); }
      }).observe(this.root);
    }
    window.partlabEditor = this; // for the browser test's measurements
  }
}

export default function (component) {
  const { data, setTriggerValue, setStateValue, parentElement } = component;
  let editor = INSTANCES.get(parentElement);
  if (!editor) {
    editor = new Editor(parentElement);
    INSTANCES.set(parentElement, editor);
  }
  editor.setTrigger = setTriggerValue;
  editor.setState = setStateValue;
  editor.update(data);
}
