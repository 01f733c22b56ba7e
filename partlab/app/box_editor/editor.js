// partlab box editor: a Streamlit components-v2 component (plain JS, no build).
//
// Python sends `data` = {image, width, height, frame, frame_count, boxes, parts, tracks,
// next_track_id, mode, applied_seq}; boxes are {track_id, part, x, y, w, h, failure,
// occluded, revision, colour}. Every user action becomes an event {seq, kind, ...};
// pending events are sent together as the trigger value "events" until Python
// reports them applied (data.applied_seq), so an action made while Python is busy
// is never dropped. Text from the user or the data is only ever set through
// textContent, never parsed as HTML.

const SVG_NS = "http://www.w3.org/2000/svg";
const HANDLE_PX = 4; // handle half-size in screen pixels (small: heads can be 10 px wide)
const MIN_SIZE = 3;  // smallest box side in image pixels
const INSTANCES = new WeakMap();

function el(name, attrs) {
  const node = document.createElementNS(SVG_NS, name);
  for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, String(v));
  return node;
}

function keyOf(b) { return b.track_id + ":" + b.part; }

// the store keeps the occluded fraction (trackers estimate it); the flag is "at least half hidden"
function isOccluded(b) { return Number(b.occluded || 0) >= 0.5; }

const SHORT = { hipleg: "hip-leg", left_hand: "L hand", right_hand: "R hand" };

class Editor {
  constructor(root) {
    this.root = root.querySelector(".pl-editor");
    this.img = root.querySelector(".pl-image");
    this.stage = root.querySelector(".pl-stage");
    this.svg = root.querySelector(".pl-overlay");
    this.frameLabel = root.querySelector(".pl-frame");
    this.status = root.querySelector(".pl-status");
    this.addPart = root.querySelector(".pl-add-part");
    this.addTrack = root.querySelector(".pl-add-track");
    this.data = null;
    this.viewFrame = 0;
    this.boxes = [];
    this.selected = null;   // "track:part" of the selected box
    this.pending = [];      // events not yet applied by Python
    this.seq = 0;
    this.drag = null;
    this.setTrigger = null;
    this.bind();
  }

  // ------------------------------------------------------------ data in
  update(data) {
    const first = this.data === null;
    this.data = data || {};
    const applied = Number(this.data.applied_seq || 0);
    this.seq = Math.max(this.seq, applied);
    this.pending = this.pending.filter((e) => e.seq > applied);
    // the frame being asked for: the newest frame request Python has not answered yet, else Python's frame
    const asked = this.pending.filter((e) => e.kind === "frame");
    this.viewFrame = asked.length ? asked[asked.length - 1].target : this.data.frame;
    if (this.img.getAttribute("src") !== this.data.image) this.img.setAttribute("src", this.data.image || "");
    this.svg.setAttribute("viewBox", `0 0 ${this.data.width || 1} ${this.data.height || 1}`);
    this.boxes = (this.data.boxes || []).map((b) => ({ ...b }));
    if (this.selected && !this.boxes.some((b) => keyOf(b) === this.selected)) this.selected = null;
    this.fillSelect(this.addPart, (this.data.parts || []).map((p) => [p, p]), this.addPart.value);
    const tracks = (this.data.tracks || []).map((t) => [String(t), "#" + t]);
    tracks.push(["new", `new (#${this.data.next_track_id})`]);
    this.fillSelect(this.addTrack, tracks, this.addTrack.value || "new");
    const occl = this.data.mode === "occluders";
    this.root.querySelector(".pl-add").style.display = occl ? "none" : "";
    for (const act of ["track", "failure", "occluded", "undo", "redo"]) {
      this.root.querySelector(`[data-act="${act}"]`).style.display = occl ? "none" : "";
    }
    this.showFrameLabel();
    if (first) this.setStatus(occl ? "draw occluder regions; drag to move, Delete removes" :
      "click a box to select it; drag to move, corners to resize, empty area to draw a new box");
    this.render();
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

  // ------------------------------------------------------------ drawing
  layout() {
    // the whole frame fits the column and 72% of the window height, small frames are scaled up
    const W = this.data.width || 1, H = this.data.height || 1;
    const cw = this.root.clientWidth || W;
    let w = cw, h = (cw * H) / W;
    const maxH = Math.max(200, window.innerHeight * 0.72);
    if (h > maxH) { h = maxH; w = (h * W) / H; }
    this.stage.style.width = `${w}px`;
    this.stage.style.height = `${h}px`;
  }

  render() {
    if (!this.data) return;
    this.layout();
    const svg = this.svg;
    while (svg.firstChild) svg.removeChild(svg.firstChild);
    const font = 11 * this.scale(); // 11 screen pixels, whatever the zoom
    const occl = this.data.mode === "occluders";
    for (const b of this.boxes) {
      const sel = keyOf(b) === this.selected;
      const cls = occl ? "pl-occluder" : ["pl-box", b.failure ? "pl-failure" : "", isOccluded(b) ? "pl-occluded" : "",
        sel ? "pl-selected" : ""].join(" ");
      const rect = el("rect", { x: b.x, y: b.y, width: b.w, height: b.h, class: cls,
        "data-track": b.track_id, "data-part": b.part });
      if (!occl) { rect.setAttribute("stroke", b.colour || "#0f0"); rect.setAttribute("fill", b.colour || "#0f0"); }
      if (sel && occl) rect.setAttribute("stroke", "#ff0");
      svg.appendChild(rect);
      if (!occl) {
        // the person's label above its box, a part's inside its top-left corner (parts sit inside the person)
        const above = b.part === "person";
        const ly = above ? Math.max(font, b.y - font * 0.3) : b.y + font;
        const label = el("text", { x: b.x + font * 0.2, y: ly, class: "pl-label", "font-size": font,
          "stroke-width": font * 0.18 });
        const flags = `${b.failure ? " FAIL" : ""}${isOccluded(b) ? " occl" : ""}`;
        label.textContent = above ? `#${b.track_id} person${flags}` : `${SHORT[b.part] || b.part}${flags}`;
        svg.appendChild(label);
      }
      if (sel) this.drawHandles(b);
    }
  }

  scale() {
    const r = this.svg.getBoundingClientRect();
    return r.width > 0 ? (this.data.width || 1) / r.width : 1;
  }

  drawHandles(b) {
    const s = HANDLE_PX * this.scale();
    for (const [name, x, y] of this.corners(b)) {
      this.svg.appendChild(el("rect", { x: x - s, y: y - s, width: 2 * s, height: 2 * s, class: `pl-handle pl-${name}` }));
    }
  }

  corners(b) {
    return [["nw", b.x, b.y], ["ne", b.x + b.w, b.y], ["sw", b.x, b.y + b.h], ["se", b.x + b.w, b.y + b.h]];
  }

  setStatus(text) { this.status.textContent = text; }

  showFrameLabel() {
    const last = Math.max(0, (this.data.frame_count || 1) - 1);
    const wait = this.viewFrame !== this.data.frame ? ` (loading ${this.viewFrame})` : "";
    this.frameLabel.textContent = `frame ${this.data.frame} / ${last}${wait}`;
  }

  // ------------------------------------------------------------ events out
  emit(event) {
    event.seq = ++this.seq;
    event.frame = this.data.frame;
    this.pending.push(event);
    if (this.setTrigger) this.setTrigger("events", this.pending.slice());
  }

  emitBox(b, extra) {
    this.emit({ kind: "edit", track_id: b.track_id, part: b.part, box: [b.x, b.y, b.w, b.h],
      failure: !!b.failure, occluded: Number(b.occluded || 0), revision: b.revision ?? null, ...extra });
    b.revision = (b.revision ?? 0) + 1; // optimistic: the next edit of this box expects our revision
  }

  emitOccluders() {
    this.emit({ kind: "occluders", boxes: this.boxes.map((b) => [b.x, b.y, b.w, b.h]) });
  }

  selectedBox() { return this.boxes.find((b) => keyOf(b) === this.selected) || null; }

  // ------------------------------------------------------------ actions
  act(name) {
    const occl = this.data.mode === "occluders";
    const b = this.selectedBox();
    if (name === "prev" || name === "next") {
      // repeated presses step on from the frame asked for last, not the one still shown
      const f = this.viewFrame + (name === "next" ? 1 : -1);
      if (f >= 0 && f < (this.data.frame_count || 0)) {
        this.viewFrame = f;
        this.emit({ kind: "frame", target: f });
        this.showFrameLabel();
      }
    } else if (name === "track") {
      this.nextTrack();
    } else if (name === "undo" || name === "redo") {
      if (!occl) this.emit({ kind: name });
    } else if (name === "delete") {
      if (!b) return this.setStatus("select a box first");
      this.boxes = this.boxes.filter((x) => x !== b);
      this.selected = null;
      if (occl) this.emitOccluders();
      else this.emit({ kind: "delete", track_id: b.track_id, part: b.part, revision: b.revision ?? null });
      this.setStatus(`deleted ${b.part} of #${b.track_id}`);
      this.render();
    } else if ((name === "failure" || name === "occluded") && !occl) {
      if (!b) return this.setStatus("select a box first");
      if (name === "failure") b.failure = !b.failure;
      else b.occluded = isOccluded(b) ? 0 : 1;
      this.emitBox(b);
      const on = name === "failure" ? b.failure : isOccluded(b);
      this.setStatus(`#${b.track_id} ${b.part}: ${name} ${on ? "on" : "off"}`);
      this.render();
    }
  }

  nextTrack() {
    if (!this.boxes.length) return;
    const order = this.boxes.slice().sort((a, b) => a.track_id - b.track_id || a.part.localeCompare(b.part));
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
    const r = this.svg.getBoundingClientRect();
    return [(ev.clientX - r.left) * (this.data.width || 1) / r.width,
      (ev.clientY - r.top) * (this.data.height || 1) / r.height];
  }

  hit(p) {
    const sel = this.selectedBox();
    const s = HANDLE_PX * this.scale() * 2; // a grab area larger than the drawn handle
    if (sel) {
      for (const [name, x, y] of this.corners(sel)) {
        if (Math.abs(p[0] - x) <= s && Math.abs(p[1] - y) <= s) return { box: sel, handle: name };
      }
    }
    const inside = this.boxes.filter((b) => p[0] >= b.x && p[0] <= b.x + b.w && p[1] >= b.y && p[1] <= b.y + b.h);
    inside.sort((a, b) => a.w * a.h - b.w * b.h); // the smallest box on top: parts inside the person
    return inside.length ? { box: inside[0], handle: null } : null;
  }

  onDown(ev) {
    if (ev.button !== 0) return;
    this.root.focus({ preventScroll: true });
    const p = this.point(ev);
    const h = this.hit(p);
    if (h) {
      this.selected = keyOf(h.box);
      this.drag = { box: h.box, handle: h.handle, start: p, orig: { x: h.box.x, y: h.box.y, w: h.box.w, h: h.box.h } };
    } else {
      const occl = this.data.mode === "occluders";
      const part = occl ? "occluder" : this.addPart.value;
      const trackValue = this.addTrack.value;
      const track = occl ? this.boxes.length : (trackValue === "new" ? this.data.next_track_id : Number(trackValue));
      if (!occl && this.boxes.some((b) => b.track_id === track && b.part === part)) {
        this.selected = null;
        this.setStatus(`track #${track} already has a ${part} box here; choose another part or track`);
        this.render();
        return;
      }
      const box = { track_id: track, part, x: p[0], y: p[1], w: 0, h: 0, failure: false, occluded: 0,
        revision: null, colour: "#ffffff", isNew: true };
      this.drag = { box, handle: "se", start: p, orig: { x: p[0], y: p[1], w: 0, h: 0 }, isNew: true };
      this.selected = null;
    }
    this.svg.setPointerCapture(ev.pointerId);
    this.render();
    ev.preventDefault();
  }

  onMove(ev) {
    const d = this.drag;
    if (!d) return;
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
    if (d.isNew && !this.boxes.includes(b)) this.boxes.push(b);
    this.render();
  }

  onUp(ev) {
    const d = this.drag;
    this.drag = null;
    if (!d) return;
    try { this.svg.releasePointerCapture(ev.pointerId); } catch (e) { /* already released */ }
    const b = d.box, o = d.orig;
    const moved = Math.abs(b.x - o.x) + Math.abs(b.y - o.y) + Math.abs(b.w - o.w) + Math.abs(b.h - o.h) > 0.5;
    if (!moved) { this.render(); return; }
    // a tenth of a pixel is plenty; a move keeps the box's size exactly
    for (const k of d.handle ? ["x", "y", "w", "h"] : ["x", "y"]) {
      if (b[k] !== o[k] || d.isNew) b[k] = Math.round(b[k] * 10) / 10;
    }
    if (d.isNew && (b.w < MIN_SIZE || b.h < MIN_SIZE)) {
      this.boxes = this.boxes.filter((x) => x !== b);
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

  onKey(ev) {
    if (ev.target && ev.target.tagName === "SELECT") return;
    const k = ev.key;
    const ctrl = ev.ctrlKey || ev.metaKey;
    let act = null;
    if (ctrl && (k === "z" || k === "Z")) act = ev.shiftKey ? "redo" : "undo";
    else if (ctrl && (k === "y" || k === "Y")) act = "redo";
    else if (ctrl || ev.altKey) return;
    else if (k === "ArrowRight" || k === "d" || k === "D") act = "next";
    else if (k === "ArrowLeft" || k === "a" || k === "A") act = "prev";
    else if (k === "Tab" || k === "n" || k === "N") act = "track";
    else if (k === "f" || k === "F") act = "failure";
    else if (k === "o" || k === "O") act = "occluded";
    else if (k === "Delete" || k === "Backspace") act = "delete";
    if (!act) return;
    ev.preventDefault();
    ev.stopPropagation();
    this.act(act);
  }

  bind() {
    this.svg.addEventListener("pointerdown", (ev) => this.onDown(ev));
    this.svg.addEventListener("pointermove", (ev) => this.onMove(ev));
    this.svg.addEventListener("pointerup", (ev) => this.onUp(ev));
    this.svg.addEventListener("pointercancel", (ev) => this.onUp(ev));
    this.root.addEventListener("keydown", (ev) => this.onKey(ev));
    for (const button of this.root.querySelectorAll("button[data-act]")) {
      button.addEventListener("click", () => { this.act(button.dataset.act); this.root.focus({ preventScroll: true }); });
    }
    this.img.addEventListener("load", () => this.render());
    if (window.ResizeObserver) {
      let last = 0;
      new ResizeObserver(() => {
        const w = this.root.clientWidth;
        if (w !== last) { last = w; this.render(); }
      }).observe(this.root);
    }
  }
}

export default function (component) {
  const { data, setTriggerValue, parentElement } = component;
  let editor = INSTANCES.get(parentElement);
  if (!editor) {
    editor = new Editor(parentElement);
    INSTANCES.set(parentElement, editor);
  }
  editor.setTrigger = setTriggerValue;
  editor.update(data);
}
