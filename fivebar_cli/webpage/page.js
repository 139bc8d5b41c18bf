/* fivebar view: draws the quadtrees and octrees embedded in this page (B/W/G bodies in the JSON
   block "fivebar-data", docs/formats.md) on canvases. Plain JavaScript, no library, no network.

   Each tree is decoded once (a preorder walk) into typed arrays of its black leaves: integer
   coordinates at the leaf's level and the level. A 2-D panel paints by area coverage into an
   ImageData at the current zoom (every leaf adds its coverage of each pixel, in its colour), so a
   quarter of a million leaves costs a few milliseconds; periodic axes are tiled (a torus). The 3-D
   view splats each leaf as its projected box into a depth buffer. After the first paint the body
   gets data-ready="true", data-cells (leaves drawn) and data-paint-ms (decoding and first paint). */
"use strict";

(function () {
  const T0 = performance.now();
  const DATA = JSON.parse(document.getElementById("fivebar-data").textContent);
  const DPR = Math.max(1, Math.min(3, window.devicePixelRatio || 1));
  const TAB10 = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];
  const OTHER = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22"];
  const FAINT = 0.1;  // weight of the aspects out of focus
  const INSIDE = "#000000", OUTSIDE = "#dcdcdc", UNDETERMINED = "#d9261a", INSIDE3D = "#3568b0";
  const MARK = "#1a59d9";  // obstacles and joint limits
  const FIRST = { active: true, drawn: new Map() };  // leaves drawn per tree during the first paint
  const panels = [];
  const probes = [];  // per aspects section: () => the highlighted aspects (for #probe)

  // ------------------------------------------------------------------ helpers

  function el(tag, attrs, parent) {
    const e = document.createElement(tag);
    if (attrs) for (const k in attrs) {
      if (k === "text") e.textContent = attrs[k];
      else if (k === "cls") e.className = attrs[k];
      else e.setAttribute(k, attrs[k]);
    }
    if (parent) parent.appendChild(e);
    return e;
  }
  function svg(tag, attrs, parent) {
    const e = document.createElementNS("http://www.w3.org/2000/svg", tag);
    for (const k in attrs) e.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(e);
    return e;
  }
  function rgb(hex) { const v = parseInt(hex.slice(1), 16); return [(v >> 16) & 255, (v >> 8) & 255, v & 255]; }
  function num(v) {
    if (v === 0) return "0";
    const a = Math.abs(v);
    const s = (a >= 1e5 || a < 1e-4) ? v.toExponential(4) : v.toPrecision(6);
    return s.indexOf("e") < 0 && s.indexOf(".") >= 0 ? s.replace(/0+$/, "").replace(/\.$/, "") : s;
  }
  function axisTitle(a) { return a[1] ? a[0] + " [" + a[1] + "]" : a[0]; }
  function wrap(v, lo, hi) { const p = hi - lo; let w = lo + ((v - lo) % p + p) % p; if (w >= hi) w = lo; return w; }
  /* Run fn at the next animation frame, or after 50 ms if no frame comes (a hidden or headless page). */
  function frame(fn) {
    let done = false;
    const run = () => { if (!done) { done = true; fn(); } };
    requestAnimationFrame(run);
    setTimeout(run, 50);
  }
  function markDrawn(index, count) {
    if (FIRST.active) FIRST.drawn.set(index, Math.max(FIRST.drawn.get(index) || 0, count));
  }

  // ------------------------------------------------------------------ decoding

  /* Black leaves of a preorder body: coordinates at their own level (bit j of a child index is
     the high half along axis j), level; plus the cell widths per level along each axis. */
  function decode(spec, index) {
    const body = spec.body, dim = spec.dim, n = body.length, nk = 1 << dim;
    let count = 0;
    for (let i = 0; i < n; i++) if (body.charCodeAt(i) === 66) count++;
    const cx = new Int32Array(count), cy = new Int32Array(count), cz = dim > 2 ? new Int32Array(count) : null;
    const lev = new Uint8Array(count);
    const px = new Int32Array(64), py = new Int32Array(64), pz = new Int32Array(64), kk = new Int32Array(64);
    let depth = 0, x = 0, y = 0, z = 0, out = 0;
    for (let i = 0; i < n; i++) {
      const c = body.charCodeAt(i);
      if (c === 71) {  // G: descend to the first child
        px[depth] = x; py[depth] = y; pz[depth] = z; kk[depth] = 0;
        depth++; x *= 2; y *= 2; z *= 2;
        continue;
      }
      if (c === 66) { cx[out] = x; cy[out] = y; if (cz) cz[out] = z; lev[out] = depth; out++; }
      while (depth > 0) {  // next sibling, or up when the siblings are done
        const d = depth - 1, k = ++kk[d];
        if (k < nk) { x = px[d] * 2 + (k & 1); y = py[d] * 2 + ((k >> 1) & 1); z = pz[d] * 2 + ((k >> 2) & 1); break; }
        depth--; x = px[d]; y = py[d]; z = pz[d];
      }
    }
    const lo = spec.root.map(r => r[0]), size = spec.root.map(r => r[1] - r[0]);
    const w = size.map(s => { const a = new Float64Array(spec.depth + 1); for (let l = 0; l <= spec.depth; l++) a[l] = s / Math.pow(2, l); return a; });
    return Object.assign({}, spec, { index: index, n: count, cx: cx, cy: cy, cz: cz, lev: lev, lo: lo, size: size, w: w, body: null });
  }

  /* Index of the leaf holding point p (first two axes; `keep` filters leaves), or -1. */
  function locate(T, p, keep) {
    const x = T.periodic[0] ? wrap(p[0], T.root[0][0], T.root[0][1]) : p[0];
    const y = T.periodic[1] ? wrap(p[1], T.root[1][0], T.root[1][1]) : p[1];
    const lx = T.lo[0], ly = T.lo[1], wx = T.w[0], wy = T.w[1], cx = T.cx, cy = T.cy, lev = T.lev;
    for (let i = 0; i < T.n; i++) {
      const l = lev[i], a = lx + cx[i] * wx[l], b = ly + cy[i] * wy[l];
      if (x >= a && x < a + wx[l] && y >= b && y < b + wy[l] && (!keep || keep(i))) return i;
    }
    return -1;
  }
  function leafBox(T, i) {
    const l = T.lev[i], c = [T.cx[i], T.cy[i], T.cz ? T.cz[i] : 0];
    const parts = [];
    for (let j = 0; j < T.dim; j++) {
      const a = T.lo[j] + c[j] * T.w[j][l];
      parts.push("[" + num(a) + ", " + num(a + T.w[j][l]) + "]");
    }
    return parts.join(" x ") + ", level " + l;
  }

  // ------------------------------------------------------------------ 2-D raster by coverage

  class Raster {
    constructor(w, h) {
      this.w = w; this.h = h;
      this.r = new Float32Array(w * h); this.g = new Float32Array(w * h);
      this.b = new Float32Array(w * h); this.a = new Float32Array(w * h);
    }
    clear() { this.r.fill(0); this.g.fill(0); this.b.fill(0); this.a.fill(0); }
    /* Adds the coverage of the rectangle [x0, x1) x [y0, y1) (pixels) in colour (r, g, b) x weight. */
    rect(x0, x1, y0, y1, r, g, b, wt) {
      const W = this.w, H = this.h;
      if (x0 < 0) x0 = 0; if (y0 < 0) y0 = 0; if (x1 > W) x1 = W; if (y1 > H) y1 = H;
      if (x1 <= x0 || y1 <= y0) return;
      const ix0 = x0 | 0, iy0 = y0 | 0, ix1 = Math.ceil(x1), iy1 = Math.ceil(y1);
      const R = this.r, G = this.g, B = this.b, A = this.a;
      if (ix1 - ix0 === 1 && iy1 - iy0 === 1) {
        const c = (x1 - x0) * (y1 - y0) * wt, k = iy0 * W + ix0;
        A[k] += c; R[k] += c * r; G[k] += c * g; B[k] += c * b;
        return;
      }
      for (let y = iy0; y < iy1; y++) {
        const fy = (Math.min(y + 1, y1) - Math.max(y, y0)) * wt, row = y * W;
        for (let x = ix0; x < ix1; x++) {
          const c = (x === ix0 || x === ix1 - 1) ? (Math.min(x + 1, x1) - Math.max(x, x0)) * fy : fy, k = row + x;
          A[k] += c; R[k] += c * r; G[k] += c * g; B[k] += c * b;
        }
      }
    }
    /* Layers over the background: bg(x, y) gives the colour where nothing covers a pixel. */
    compose(image, inX, inY, bgIn) {
      const d = image.data, W = this.w, H = this.h, R = this.r, G = this.g, B = this.b, A = this.a;
      for (let y = 0; y < H; y++) {
        for (let x = 0; x < W; x++) {
          const k = y * W + x, o = 4 * k, a = A[k];
          const inside = bgIn && inX[x] && inY[y];
          const br = inside ? bgIn[0] : 255, bgc = inside ? bgIn[1] : 255, bb = inside ? bgIn[2] : 255;
          if (a >= 1) { d[o] = R[k] / a; d[o + 1] = G[k] / a; d[o + 2] = B[k] / a; }
          else { d[o] = R[k] + (1 - a) * br; d[o + 1] = G[k] + (1 - a) * bgc; d[o + 2] = B[k] + (1 - a) * bb; }
          d[o + 3] = 255;
        }
      }
    }
  }

  function niceStep(span, target) {
    const raw = span / Math.max(1, target), p = Math.pow(10, Math.floor(Math.log10(raw))), f = raw / p;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
  }
  function tickText(v, step) {
    const dec = Math.max(0, Math.min(10, Math.ceil(-Math.log10(step) - 1e-9)));
    const s = v.toFixed(dec);
    return s === "-0" || /^-0\.0*$/.test(s) ? s.slice(1) : s;
  }
  function tiles(lo, hi, periodic, v0, v1) {  // offsets of the copies of [lo, hi] meeting [v0, v1]
    if (!periodic) return [0];
    const p = hi - lo, out = [];
    for (let k = Math.ceil((v0 - hi) / p); k <= Math.floor((v1 - lo) / p); k++) out.push(k * p);
    return out;
  }

  /* A 2-D view of trees: layers {tree, color, visible, weight(), keep, label}; zoom, pan, hover. */
  class Panel2D {
    constructor(host, spec) {
      this.spec = spec;
      this.axes = spec.axes; this.root = spec.root; this.periodic = spec.periodic; this.layers = spec.layers;
      const css = spec.size, ML = 56, MR = 10, MT = 6, MB = 38;
      this.m = { l: ML, r: MR, t: MT, b: MB }; this.pw = css; this.ph = css;
      const box = el("div", { cls: "panel" }, host);
      box.style.width = (css + ML + MR) + "px";
      if (spec.title) el("h3", { text: spec.title }, box);
      if (spec.tools) spec.tools(el("div", { cls: "tools" }, box));
      const cv = el("canvas", {}, box);
      cv.style.width = (css + ML + MR) + "px"; cv.style.height = (css + MT + MB) + "px";
      cv.width = Math.round((css + ML + MR) * DPR); cv.height = Math.round((css + MT + MB) * DPR);
      this.canvas = cv; this.ctx = cv.getContext("2d");
      this.readout = el("div", { cls: "readout", text: " " }, box);
      this.readout.style.width = (css + ML + MR) + "px";
      this.dw = Math.round(css * DPR); this.dh = Math.round(css * DPR);
      this.raster = new Raster(this.dw, this.dh);
      this.image = this.ctx.createImageData(this.dw, this.dh);
      this.equal = this.axes[0][1] === this.axes[1][1];
      this.reset();
      this.bind();
      this.pending = false; this.hoverAt = null;
      panels.push(this);
    }
    reset() {
      const [[x0, x1], [y0, y1]] = this.root, w = x1 - x0, h = y1 - y0, pad = 1.04;
      let sx = this.pw / (w * pad), sy = this.ph / (h * pad);
      if (this.equal) sx = sy = Math.min(sx, sy);
      this.sx = sx; this.sy = sy; this.fitSx = sx;
      this.vx0 = (x0 + x1) / 2 - this.pw / (2 * sx); this.vy0 = (y0 + y1) / 2 - this.ph / (2 * sy);
    }
    world(px, py) { return [this.vx0 + px / this.sx, this.vy0 + (this.ph - py) / this.sy]; }
    screen(x, y) { return [(x - this.vx0) * this.sx, this.ph - (y - this.vy0) * this.sy]; }
    request() {
      if (this.pending) return;
      this.pending = true;
      frame(() => { this.pending = false; this.render(); if (this.hoverAt) this.hover(this.hoverAt); });
    }
    bind() {
      const cv = this.canvas;
      let drag = null;
      const pos = e => { const r = cv.getBoundingClientRect(); return [e.clientX - r.left - this.m.l, e.clientY - r.top - this.m.t]; };
      cv.addEventListener("wheel", e => {
        e.preventDefault();
        const [px, py] = pos(e), [wx, wy] = this.world(px, py);
        const f = Math.exp(-e.deltaY * (e.deltaMode ? 0.05 : 0.0015));
        const deepest = Math.max.apply(null, this.layers.map(L => L.tree.depth));
        const nsx = Math.min(Math.max(this.sx * f, this.fitSx / 4), this.fitSx * Math.pow(2, deepest + 4));
        const g = nsx / this.sx;
        this.sx *= g; this.sy *= g;
        this.vx0 = wx - px / this.sx; this.vy0 = wy - (this.ph - py) / this.sy;
        this.request();
      }, { passive: false });
      let moved = false;
      cv.addEventListener("mousedown", e => { drag = { p: pos(e), moved: false }; });
      window.addEventListener("mouseup", () => { if (drag) moved = drag.moved; drag = null; });
      cv.addEventListener("mousemove", e => {
        const p = pos(e);
        if (drag && e.buttons) {
          const dx = p[0] - drag.p[0], dy = p[1] - drag.p[1];
          if (Math.abs(dx) + Math.abs(dy) > 0) drag.moved = true;
          this.vx0 -= dx / this.sx; this.vy0 += dy / this.sy; drag.p = p;
          this.request();
        }
        this.hoverAt = p;
        this.requestHover();
      });
      cv.addEventListener("mouseleave", () => { this.hoverAt = null; if (this.spec.onLeave) this.spec.onLeave(); });
      cv.addEventListener("click", () => { if (this.spec.onClick && !moved) this.spec.onClick(); moved = false; });
      cv.addEventListener("dblclick", () => { this.reset(); this.request(); });
    }
    requestHover() {
      if (this.hoverPending) return;
      this.hoverPending = true;
      frame(() => { this.hoverPending = false; if (this.hoverAt) this.hover(this.hoverAt); });
    }
    hover(p) {
      if (p[0] < 0 || p[1] < 0 || p[0] > this.pw || p[1] > this.ph) { this.readout.textContent = " "; return; }
      const w = this.world(p[0], p[1]);
      const shown = w.map((v, j) => this.periodic[j] ? wrap(v, this.root[j][0], this.root[j][1]) : v);
      const hits = [];
      for (const L of this.layers) {
        if (!L.visible) continue;
        const i = locate(L.tree, w, L.keep);
        if (i >= 0) hits.push({ layer: L, leaf: i });
      }
      const head = this.axes.map((a, j) => a[0] + " = " + num(shown[j])).join(", ");
      this.readout.textContent = head + "\n" + this.spec.describe(hits, shown);
      if (this.spec.onHover) this.spec.onHover(hits);
    }
    render() {
      const R = this.raster, dpr = DPR, sx = this.sx * dpr, sy = this.sy * dpr, W = this.dw, H = this.dh;
      const vx0 = this.vx0, vy0 = this.vy0, vx1 = vx0 + W / sx, vy1 = vy0 + H / sy;
      R.clear();
      for (const L of this.layers) {
        if (!L.visible) { continue; }
        const T = L.tree, wt = L.weight ? L.weight() : 1, col = L.rgb || (L.rgb = rgb(L.color));
        const txs = tiles(T.root[0][0], T.root[0][1], T.periodic[0], vx0, vx1);
        const tys = tiles(T.root[1][0], T.root[1][1], T.periodic[1], vy0, vy1);
        const cx = T.cx, cy = T.cy, lev = T.lev, wx = T.w[0], wy = T.w[1], lx = T.lo[0], ly = T.lo[1], keep = L.keep;
        const r = col[0], g = col[1], b = col[2];
        let drawn = 0;
        for (let i = 0; i < T.n; i++) {
          if (keep && !keep(i)) continue;
          const l = lev[i], ax = lx + cx[i] * wx[l], ay = ly + cy[i] * wy[l], pw = wx[l] * sx, ph = wy[l] * sy;
          let hit = false;
          for (let s = 0; s < txs.length; s++) {
            const X0 = (ax + txs[s] - vx0) * sx;
            if (X0 >= W || X0 + pw <= 0) continue;
            for (let t = 0; t < tys.length; t++) {
              const Y0 = (vy1 - (ay + tys[t]) ) * sy - ph;
              if (Y0 >= H || Y0 + ph <= 0) continue;
              R.rect(X0, X0 + pw, Y0, Y0 + ph, r, g, b, wt);
              hit = true;
            }
          }
          if (hit) drawn++;
        }
        L.drawn = drawn;
        markDrawn(T.index, drawn);
      }
      const bg = this.spec.background && this.spec.background.visible ? (this.spec.background.rgb || (this.spec.background.rgb = rgb(this.spec.background.color))) : null;
      const inX = new Uint8Array(W), inY = new Uint8Array(H);
      if (bg) {
        const [[x0, x1], [y0, y1]] = this.root;
        for (let x = 0; x < W; x++) { const v = vx0 + (x + 0.5) / sx; inX[x] = this.periodic[0] || (v >= x0 && v <= x1) ? 1 : 0; }
        for (let y = 0; y < H; y++) { const v = vy1 - (y + 0.5) / sy; inY[y] = this.periodic[1] || (v >= y0 && v <= y1) ? 1 : 0; }
      }
      R.compose(this.image, inX, inY, bg);
      const ctx = this.ctx, m = this.m;
      ctx.setTransform(1, 0, 0, 1, 0, 0);
      ctx.clearRect(0, 0, this.canvas.width, this.canvas.height);
      ctx.putImageData(this.image, Math.round(m.l * dpr), Math.round(m.t * dpr));
      ctx.setTransform(dpr, 0, 0, dpr, m.l * dpr, m.t * dpr);
      ctx.save();
      ctx.beginPath(); ctx.rect(0, 0, this.pw, this.ph); ctx.clip();
      this.drawFrame(ctx);
      if (this.spec.overlay) this.spec.overlay(ctx, this);
      ctx.restore();
      this.drawAxes(ctx);
    }
    drawFrame(ctx) {  // the root box, or the seams of a periodic axis (dashed)
      const [[x0, x1], [y0, y1]] = this.root;
      ctx.lineWidth = 1; ctx.strokeStyle = "#888";
      ctx.setLineDash(this.periodic[0] || this.periodic[1] ? [4, 4] : []);
      const vx1 = this.vx0 + this.pw / this.sx, vy1 = this.vy0 + this.ph / this.sy;
      for (const tx of tiles(x0, x1, this.periodic[0], this.vx0, vx1)) {
        for (const ty of tiles(y0, y1, this.periodic[1], this.vy0, vy1)) {
          const [a, b] = this.screen(x0 + tx, y1 + ty), [c, d] = this.screen(x1 + tx, y0 + ty);
          ctx.strokeRect(a, b, c - a, d - b);
        }
      }
      ctx.setLineDash([]);
    }
    drawAxes(ctx) {
      const pw = this.pw, ph = this.ph;
      ctx.strokeStyle = "#333"; ctx.lineWidth = 1; ctx.strokeRect(0, 0, pw, ph);
      ctx.fillStyle = "#222"; ctx.font = "11px system-ui, sans-serif";
      for (let j = 0; j < 2; j++) {
        const v0 = j ? this.vy0 : this.vx0, span = j ? ph / this.sy : pw / this.sx, step = niceStep(span, 6);
        const [lo, hi] = this.root[j], ticks = [];
        if (this.periodic[j]) {  // multiples of the step inside the root interval, repeated on each copy
          for (const o of tiles(lo, hi, true, v0, v0 + span)) {
            for (let k = Math.ceil(lo / step); k * step < hi - 1e-9 * step; k++) {
              const v = k * step + o;
              if (v >= v0 && v <= v0 + span) ticks.push([v, tickText(k * step, step)]);
            }
          }
        } else {
          for (let k = Math.ceil(v0 / step); k * step <= v0 + span; k++) ticks.push([k * step, tickText(k * step, step)]);
        }
        for (const [v, label] of ticks) {
          if (j === 0) {
            const x = (v - v0) * this.sx;
            ctx.beginPath(); ctx.moveTo(x, ph); ctx.lineTo(x, ph + 4); ctx.stroke();
            ctx.textAlign = "center"; ctx.textBaseline = "top"; ctx.fillText(label, x, ph + 5);
          } else {
            const y = ph - (v - v0) * this.sy;
            ctx.beginPath(); ctx.moveTo(0, y); ctx.lineTo(-4, y); ctx.stroke();
            ctx.textAlign = "right"; ctx.textBaseline = "middle"; ctx.fillText(label, -6, y);
          }
        }
      }
      ctx.font = "12px system-ui, sans-serif"; ctx.textAlign = "center";
      ctx.textBaseline = "bottom"; ctx.fillText(axisTitle(this.axes[0]), pw / 2, ph + this.m.b);
      ctx.save(); ctx.translate(-this.m.l + 2, ph / 2); ctx.rotate(-Math.PI / 2);
      ctx.textBaseline = "top"; ctx.fillText(axisTitle(this.axes[1]), 0, 0); ctx.restore();
    }
  }

  // ------------------------------------------------------------------ 3-D view of octrees

  class Panel3D {
    constructor(host, spec) {
      this.spec = spec; this.layers = spec.layers;
      const css = spec.size;
      const box = el("div", { cls: "panel" }, host);
      el("h3", { text: spec.title }, box);
      const cv = el("canvas", { cls: "rotate" }, box);
      cv.style.width = css + "px"; cv.style.height = css + "px";
      cv.width = Math.round(css * DPR); cv.height = Math.round(css * DPR);
      this.css = css; this.canvas = cv; this.ctx = cv.getContext("2d");
      this.w = cv.width; this.h = cv.height;
      this.image = this.ctx.createImageData(this.w, this.h);
      this.zbuf = new Float32Array(this.w * this.h);
      el("div", { cls: "readout", text: "drag: rotate, wheel: zoom, double-click: reset\nsolid: trees shown; dots: complements (cell centres)" }, box).style.width = css + "px";
      this.reset(); this.bind(); this.pending = false;
      panels.push(this);
    }
    reset() { this.yaw = -0.65; this.pitch = 0.45; this.zoom = 1; }
    request() {
      if (this.pending) return;
      this.pending = true;
      frame(() => { this.pending = false; this.render(); });
    }
    bind() {
      const cv = this.canvas;
      let last = null;
      cv.addEventListener("mousedown", e => { last = [e.clientX, e.clientY]; });
      window.addEventListener("mouseup", () => { last = null; });
      cv.addEventListener("mousemove", e => {
        if (!last || !e.buttons) return;
        this.yaw += (e.clientX - last[0]) * 0.01;
        this.pitch = Math.max(-1.55, Math.min(1.55, this.pitch + (e.clientY - last[1]) * 0.01));
        last = [e.clientX, e.clientY]; this.request();
      });
      cv.addEventListener("wheel", e => {
        e.preventDefault();
        this.zoom = Math.max(0.3, Math.min(40, this.zoom * Math.exp(-e.deltaY * (e.deltaMode ? 0.05 : 0.0015))));
        this.request();
      }, { passive: false });
      cv.addEventListener("dblclick", () => { this.reset(); this.request(); });
    }
    matrix() {
      const a = Math.cos(this.yaw), b = Math.sin(this.yaw), cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
      return { X: [a, -b, 0], Y: [b * sp, a * sp, cp], D: [b * cp, a * cp, -sp] };
    }
    project(M, n) {  // normalised point (each axis in [-0.5, 0.5]) -> [screen x, screen y, depth]
      const S = this.zoom * this.w * 0.56, c = this.w / 2, d = this.h / 2;
      return [c + S * (M.X[0] * n[0] + M.X[1] * n[1] + M.X[2] * n[2]),
        d - S * (M.Y[0] * n[0] + M.Y[1] * n[1] + M.Y[2] * n[2]),
        M.D[0] * n[0] + M.D[1] * n[1] + M.D[2] * n[2]];
    }
    render() {
      const W = this.w, H = this.h, Z = this.zbuf, px = new Uint32Array(this.image.data.buffer);
      px.fill(0xffffffff); Z.fill(Infinity);
      const M = this.matrix(), S = this.zoom * W * 0.56, c0 = W / 2, c1 = H / 2;
      const ordered = this.layers.filter(L => L.visible && L.style === "solid").concat(this.layers.filter(L => L.visible && L.style === "dots"));
      for (const L of ordered) {
        const T = L.tree, col = L.rgb3 || (L.rgb3 = rgb(L.color3d));
        const lo = T.lo, size = T.size, w = T.w, cx = T.cx, cy = T.cy, cz = T.cz, lev = T.lev;
        const X = M.X, Y = M.Y, D = M.D;
        const ex = [Math.abs(X[0]), Math.abs(X[1]), Math.abs(X[2])], ey = [Math.abs(Y[0]), Math.abs(Y[1]), Math.abs(Y[2])];
        const half = [], n0 = new Float64Array(T.depth + 1), n1 = new Float64Array(T.depth + 1), n2 = new Float64Array(T.depth + 1);
        for (let l = 0; l <= T.depth; l++) {
          n0[l] = w[0][l] / size[0]; n1[l] = w[1][l] / size[1]; n2[l] = w[2][l] / size[2];
          half.push([S * 0.5 * (ex[0] * n0[l] + ex[1] * n1[l] + ex[2] * n2[l]), S * 0.5 * (ey[0] * n0[l] + ey[1] * n1[l] + ey[2] * n2[l])]);
        }
        let drawn = 0;
        const dots = L.style === "dots";
        for (let i = 0; i < T.n; i++) {
          const l = lev[i];
          const a = (cx[i] + 0.5) * n0[l] - 0.5, b = (cy[i] + 0.5) * n1[l] - 0.5, e = (cz[i] + 0.5) * n2[l] - 0.5;
          const sx = c0 + S * (X[0] * a + X[1] * b + X[2] * e), sy = c1 - S * (Y[0] * a + Y[1] * b + Y[2] * e);
          const dz = D[0] * a + D[1] * b + D[2] * e;
          const shade = Math.max(0.25, Math.min(1, 0.95 - 0.6 * (dz + 0.5)));
          const colour = (255 << 24) | ((col[2] * shade) << 16) | ((col[1] * shade) << 8) | (col[0] * shade);
          if (dots) {
            const x = sx | 0, y = sy | 0;
            if (x < 0 || y < 0 || x >= W || y >= H) continue;
            const k = y * W + x;
            if (dz < Z[k]) px[k] = colour;
            drawn++;
            continue;
          }
          const hx = Math.max(0.5, half[l][0]), hy = Math.max(0.5, half[l][1]);
          let x0 = Math.floor(sx - hx), x1 = Math.ceil(sx + hx), y0 = Math.floor(sy - hy), y1 = Math.ceil(sy + hy);
          if (x1 <= 0 || y1 <= 0 || x0 >= W || y0 >= H) continue;
          if (x0 < 0) x0 = 0; if (y0 < 0) y0 = 0; if (x1 > W) x1 = W; if (y1 > H) y1 = H;
          for (let y = y0; y < y1; y++) {
            const row = y * W;
            for (let x = x0; x < x1; x++) { const k = row + x; if (dz < Z[k]) { Z[k] = dz; px[k] = colour; } }
          }
          drawn++;
        }
        L.drawn = drawn;
        markDrawn(T.index, drawn);
      }
      const ctx = this.ctx;
      ctx.setTransform(1, 0, 0, 1, 0, 0);
      ctx.putImageData(this.image, 0, 0);
      this.drawBox(ctx, M);
    }
    drawBox(ctx, M) {
      const P = n => this.project(M, n), h = 0.5;
      const corners = [];
      for (let k = 0; k < 8; k++) corners.push([(k & 1) ? h : -h, (k & 2) ? h : -h, (k & 4) ? h : -h]);
      ctx.strokeStyle = "#777"; ctx.lineWidth = DPR;
      for (let k = 0; k < 8; k++) for (let j = 0; j < 3; j++) {
        if (k & (1 << j)) continue;
        const a = P(corners[k]), b = P(corners[k | (1 << j)]);
        ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.stroke();
      }
      const s = this.spec.sliceValue ? this.spec.sliceValue() : null;
      if (s !== null) {
        const z = s - 0.5, q = [[-h, -h, z], [h, -h, z], [h, h, z], [-h, h, z]].map(P);
        ctx.strokeStyle = "#e67e22"; ctx.lineWidth = 2 * DPR; ctx.beginPath();
        q.forEach((p, i) => i ? ctx.lineTo(p[0], p[1]) : ctx.moveTo(p[0], p[1]));
        ctx.closePath(); ctx.stroke();
      }
      ctx.fillStyle = "#222"; ctx.font = (12 * DPR) + "px system-ui, sans-serif"; ctx.textAlign = "center"; ctx.textBaseline = "middle";
      const axes = this.spec.axes;
      for (let j = 0; j < 3; j++) {  // each axis named beside its edge through the low corner
        const m = [-0.6, -0.6, -0.6];
        m[j] = 0;
        const p = P(m), [lo, hi] = this.spec.root[j];
        const text = axisTitle(axes[j]) + " " + num(lo) + ".." + num(hi), half = ctx.measureText(text).width / 2 + 4 * DPR;
        ctx.fillText(text, Math.max(half, Math.min(this.w - half, p[0])), Math.max(8 * DPR, Math.min(this.h - 8 * DPR, p[1])));
      }
    }
  }

  // ------------------------------------------------------------------ legends

  function legendRow(table, colour, label, checked, onToggle, title) {
    const tr = el("tr", {}, table);
    const box = el("input", { type: "checkbox" }, el("td", {}, tr));
    box.checked = checked;
    box.addEventListener("change", () => onToggle(box.checked));
    const sw = el("span", { cls: "swatch" }, el("td", {}, tr));
    sw.style.background = colour;
    const td = el("td", { text: label }, tr);
    if (title) tr.title = title;
    return { tr: tr, box: box, td: td };
  }
  function treeText(t) {
    const what = t.role === "inside" ? "certified inside" : t.role === "outside" ? "certified outside" : (t.region || "tree");
    return t.label + ": " + what + " (" + t.leaves + " leaves, " + (t.dim === 2 ? "area " : "volume ") + num(t.measure) + ")";
  }
  function treeTitle(t) {
    const lines = [t.label, "depth " + t.depth + ", root " + t.root.map(r => "[" + num(r[0]) + ", " + num(r[1]) + "]").join(" x ")];
    for (const k in t.fields) lines.push(k + ": " + t.fields[k]);
    return lines.join("\n");
  }
  function panelSize(columns) {  // plot side (CSS px) so that `columns` panels and the side column fit
    const avail = (window.innerWidth || 1200) - 28 - 20 - 260 - 10 * columns;  // padding, scroll bar, side column
    return Math.max(260, Math.min(560, Math.floor(avail / columns) - 66));
  }

  // ------------------------------------------------------------------ overlays: path, circles, squares

  function drawPath(ctx, panel, table) {
    if (!table) return;
    const ix = table.columns.indexOf(panel.axes[0][0]), iy = table.columns.indexOf(panel.axes[1][0]);
    if (ix < 0 || iy < 0 || table.rows.length === 0) return;
    const vx1 = panel.vx0 + panel.pw / panel.sx, vy1 = panel.vy0 + panel.ph / panel.sy;
    const [[x0, x1], [y0, y1]] = panel.root, px = x1 - x0, py = y1 - y0;
    ctx.lineWidth = 2.5; ctx.strokeStyle = "#ff00aa"; ctx.lineJoin = "round";
    for (const tx of tiles(x0, x1, panel.periodic[0], panel.vx0, vx1)) for (const ty of tiles(y0, y1, panel.periodic[1], panel.vy0, vy1)) {
      ctx.beginPath();
      let prev = null;
      for (const row of table.rows) {
        const x = row[ix], y = row[iy];
        const jump = prev && ((panel.periodic[0] && Math.abs(x - prev[0]) > px / 2) || (panel.periodic[1] && Math.abs(y - prev[1]) > py / 2));
        const p = panel.screen(x + tx, y + ty);
        if (!prev || jump) ctx.moveTo(p[0], p[1]); else ctx.lineTo(p[0], p[1]);
        prev = [x, y];
      }
      ctx.stroke();
    }
    const first = table.rows[0], last = table.rows[table.rows.length - 1];
    ctx.fillStyle = "#ff00aa";
    for (const r of [first, last]) { const p = panel.screen(r[ix], r[iy]); ctx.beginPath(); ctx.arc(p[0], p[1], 4, 0, 2 * Math.PI); ctx.fill(); }
  }

  function drawMarks(ctx, panel, marks) {  // obstacles (workspace) and joint limits (joint space), in blue
    if (!marks || !marks.length) return;
    ctx.save(); ctx.strokeStyle = MARK; ctx.fillStyle = "rgba(26, 89, 217, 0.25)"; ctx.lineWidth = 2;
    const [[x0, x1], [y0, y1]] = panel.root;
    const outline = (m, grow) => {  // the shape, or its outline grown by the clearance (corners cut)
      ctx.beginPath();
      if (m.kind === "disc") { const c = panel.screen(m.centre[0], m.centre[1]); ctx.arc(c[0], c[1], (m.radius + grow) * panel.sx, 0, 2 * Math.PI); return; }
      m.points.forEach((q, k) => { const p = panel.screen(q[0], q[1]); if (k) ctx.lineTo(p[0], p[1]); else ctx.moveTo(p[0], p[1]); });
      ctx.closePath();
    };
    for (const m of marks) {
      ctx.setLineDash([]);
      if (m.kind === "line") {
        const a = m.axis === 0 ? panel.screen(m.value, y0) : panel.screen(x0, m.value), b = m.axis === 0 ? panel.screen(m.value, y1) : panel.screen(x1, m.value);
        ctx.setLineDash([6, 4]); ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.stroke();
        continue;
      }
      outline(m, 0); ctx.fill(); ctx.stroke();
      if (m.clearance > 0 && m.kind === "disc") { ctx.setLineDash([4, 3]); outline(m, m.clearance); ctx.stroke(); }
    }
    ctx.restore();
  }

  // ------------------------------------------------------------------ sections

  function pavingLayers(sec, trees) {
    let other = 0, outside = 0;
    return sec.layers.map((ly, k) => {
      const t = trees[ly.tree];
      let color, color3d;
      if (ly.role === "inside" && k === 0) { color = INSIDE; color3d = INSIDE3D; }
      else if (ly.role === "outside") { color = outside++ ? "#b8c7d9" : OUTSIDE; color3d = "#8a8a8a"; }
      else { color = color3d = OTHER[other++ % OTHER.length]; }
      return { tree: t, color: color, color3d: color3d, visible: true, label: treeText(t), title: treeTitle(t),
        style: ly.role === "outside" ? "dots" : "solid", role: ly.role };
    });
  }

  function describeHits(hits, point, sec, trees) {
    const lines = hits.map(h => h.layer.label.split(":")[0] + ": " + (h.layer.role === "inside" ? "inside" : h.layer.role === "outside" ? "outside" : "black")
      + ", cell " + leafBox(h.layer.tree, h.leaf));
    if (!hits.length && sec.undetermined) {
      const T = trees[sec.undetermined.inside], n = Math.pow(2, T.depth), idx = [];
      let inRoot = true;
      for (let j = 0; j < 2; j++) {
        const f = (point[j] - T.lo[j]) / T.size[j];
        if (f < 0 || f > 1) inRoot = false;
        idx.push(Math.min(n - 1, Math.floor(f * n)));
      }
      if (inRoot) {
        const box = idx.map((c, j) => "[" + num(T.lo[j] + c * T.w[j][T.depth]) + ", " + num(T.lo[j] + (c + 1) * T.w[j][T.depth]) + "]").join(" x ");
        lines.push("undetermined: depth-" + T.depth + " cell " + box);
      }
    }
    return lines.length ? lines.join("\n") : "no cell of a shown tree here";
  }

  function buildPaving(host, sec, trees) {
    const layers = pavingLayers(sec, trees), t0 = trees[sec.layers[0].tree];
    const row = el("div", { cls: "row" }, host);
    const background = sec.undetermined ? { color: UNDETERMINED, visible: true } : null;
    const panel = new Panel2D(row, {
      axes: t0.axes, root: t0.root, periodic: t0.periodic, layers: layers, background: background, size: panelSize(1),
      describe: (hits, p) => describeHits(hits, p, sec, trees),
      overlay: (ctx, pn) => { drawMarks(ctx, pn, t0.marks); drawPath(ctx, pn, sec.path === null ? null : DATA.paths[sec.path]); },
    });
    const side = el("div", { cls: "side" }, row), table = el("table", { cls: "legend" }, side);
    for (const L of layers) legendRow(table, L.color, L.label, true, v => { L.visible = v; panel.request(); }, L.title);
    if (t0.marks && t0.marks.length) el("p", { cls: "note", text: "Blue: " + t0.marks.map(m => m.label).filter((x, k, a) => a.indexOf(x) === k).join(", ") + "." }, side);
    if (background) legendRow(table, UNDETERMINED, "undetermined (in neither tree, at depth " + t0.depth + ")", true, v => { background.visible = v; panel.request(); });
    if (t0.periodic.some(x => x)) el("p", { cls: "note", text: "Periodic axes (a torus): panning across the seams (dashed) continues on the other side." }, side);
    return [panel];
  }

  /* A slider along the third axis (inserted before `row`), the slice through it (a 2-D panel:
     `spec` adds its background, describe and hover callbacks) and the 3-D view, of octree layers. */
  function sliceAndSolid(host, row, layers, t0, size, spec) {
    const depth = Math.max.apply(null, layers.map(L => L.tree.depth)), n = Math.pow(2, depth);
    const state = { layer: n >> 1 };
    const fraction = () => (state.layer + 0.5) / n;
    const sliceKeep = T => {
      const m = Math.pow(2, T.depth), cz = T.cz, lev = T.lev;
      return i => { const L = Math.min(m - 1, Math.floor(fraction() * m)), span = Math.pow(2, T.depth - lev[i]); return cz[i] * span <= L && L < (cz[i] + 1) * span; };
    };
    const sliceLayers = layers.map(L => Object.assign({}, L, { keep: sliceKeep(L.tree) }));
    const ctl = el("div", { cls: "slider" });
    host.insertBefore(ctl, row);
    const ax = t0.axes[2], [zlo, zhi] = t0.root[2];
    el("span", { text: "slice " + axisTitle(ax) + ":" }, ctl);
    const input = el("input", { type: "range", min: "0", max: String(n - 1), step: "1", value: String(state.layer) }, ctl);
    const label = el("span", {}, ctl);
    const slice = new Panel2D(row, Object.assign({
      title: "slice", axes: t0.axes.slice(0, 2), root: t0.root.slice(0, 2), periodic: t0.periodic.slice(0, 2),
      layers: sliceLayers, background: null, size: size,
    }, spec));
    const view3d = new Panel3D(row, { title: "3-D (drag to rotate)", axes: t0.axes, root: t0.root, layers: layers, size: size + 44,
      sliceValue: () => fraction() });
    const setLabel = () => {
      const a = zlo + (zhi - zlo) * state.layer / n, b = zlo + (zhi - zlo) * (state.layer + 1) / n;
      label.textContent = ax[0] + " in [" + num(a) + ", " + num(b) + "]" + (ax[1] ? " " + ax[1] : "") + " (layer " + (state.layer + 1) + " of " + n + ")" + (t0.periodic[2] ? ", periodic" : "");
    };
    setLabel();
    input.addEventListener("input", () => { state.layer = +input.value; setLabel(); slice.request(); view3d.request(); });
    return { slice: slice, view3d: view3d, sliceLayers: sliceLayers };
  }

  function buildOctree(host, sec, trees) {
    const layers = pavingLayers(sec, trees), t0 = trees[sec.layers[0].tree];
    const row = el("div", { cls: "row" }, host);
    const size = panelSize(2);
    const background = sec.undetermined ? { color: UNDETERMINED, visible: true } : null;
    const { slice, view3d, sliceLayers } = sliceAndSolid(host, row, layers, t0, size, {
      background: background, describe: (hits, p) => describeHits(hits, p, sec, trees),
    });
    const side = el("div", { cls: "side" }, row), table = el("table", { cls: "legend" }, side);
    layers.forEach((L, k) => legendRow(table, L.color, L.label, true, v => { L.visible = v; sliceLayers[k].visible = v; slice.request(); view3d.request(); }, L.title));
    if (background) legendRow(table, UNDETERMINED, "undetermined (slice only)", true, v => { background.visible = v; slice.request(); });
    return [slice, view3d];
  }

  function buildAspects(host, sec, trees) {
    const info = new Map(sec.aspects.map(a => [a.aspect, a]));
    const colour = a => TAB10[(a - 1) % 10];
    const state = { visible: new Map(sec.aspects.map(a => [a.aspect, true])), hover: new Set(), pinned: new Set() };
    const active = () => state.pinned.size ? state.pinned : state.hover;
    /* Full colour: the highlighted aspects, else those of the panel's focus mode; the others faint. */
    const weight = (a, panel) => () => {
      const h = active();
      if (h.size) return h.has(a) ? 1 : FAINT;
      const r = info.get(a);
      return panel.focus === null || !r || r[panel.focusKey] === panel.focus ? 1 : FAINT;
    };
    const modes = a => { const r = info.get(a) || {}; return (r.working_mode ? "working mode " + r.working_mode : "") + (r.assembly_mode ? ", assembly mode " + r.assembly_mode : "") + (r.det_sign ? "det J " + r.det_sign : "") + (r.certified === "true" ? " (certified)" : r.certified === "false" ? " (not certified)" : ""); };
    const row = el("div", { cls: "row" }, host);
    const solid = sec.panels.some(p => trees[p.layers[0].tree].dim === 3);  // aspects of octrees: a slice and a 3-D view
    const size = panelSize(solid ? 2 : sec.panels.length);
    const views = [];
    let legendRows = new Map(), graphNodes = new Map();
    const refresh = () => {
      views.forEach(v => v.request());
      const h = active();
      legendRows.forEach((tr, a) => { tr.className = h.has(a) ? "hl" : ""; });
      graphNodes.forEach((c, a) => { c.setAttribute("stroke-width", h.has(a) ? 4 : 1); c.setAttribute("stroke", h.has(a) ? "#000" : "#444"); });
    };
    const setHover = set => {
      const same = set.size === state.hover.size && [...set].every(a => state.hover.has(a));
      if (!same) { state.hover = set; refresh(); }
    };
    const pin = set => { state.pinned = set; refresh(); };
    for (const p of sec.panels) {
      const t0 = trees[p.layers[0].tree];
      // the workspace is paved once per working mode, the joint space once per assembly mode:
      // within one such mode the aspects do not overlap, so that is what a panel focuses on
      const focus = { focusKey: p.space === "workspace" ? "working_mode" : "assembly_mode", focus: null };
      const groups = [...new Set(p.layers.map(ly => (info.get(ly.aspect) || {})[focus.focusKey]).filter(x => x))];
      focus.focus = groups.length > 1 ? groups[0] : null;
      const layers = p.layers.map(ly => ({ tree: trees[ly.tree], aspect: ly.aspect, color: colour(ly.aspect), color3d: colour(ly.aspect), style: "solid", visible: true, weight: weight(ly.aspect, focus), label: "aspect " + ly.aspect }));
      const describeAspects = hits => hits.length ? hits.map(h => "aspect " + h.layer.aspect + ": " + modes(h.layer.aspect) + "\n  cell " + leafBox(h.layer.tree, h.leaf)).join("\n") : "in no shown aspect (white: not certified in one)";
      if (t0.dim === 3) {
        const { slice, view3d, sliceLayers } = sliceAndSolid(host, row, layers, t0, size, {
          title: (p.space || "tree") + " slice (" + t0.axes.slice(0, 2).map(axisTitle).join(", ") + ")", describe: describeAspects,
          onHover: hits => setHover(new Set(hits.map(h => h.layer.aspect))), onLeave: () => setHover(new Set()),
          onClick: () => pin(state.pinned.size ? new Set() : new Set(state.hover)),
          overlay: (ctx, pn) => drawPath(ctx, pn, sec.path === null ? null : DATA.paths[sec.path]),
        });
        slice.aspectLayers = sliceLayers;
        view3d.aspectLayers = layers;
        views.push(slice, view3d);
        continue;
      }
      const xy = t0.axes[0][0] === "x" && t0.axes[1][0] === "y";
      const tools = box => {
        if (groups.length < 2) return;
        el("span", { text: focus.focusKey.replace("_", " ") + ": " }, box);
        const buttons = [];
        const add = (text, value) => {
          const b = el("button", { text: text, title: value === null ? "every aspect in full colour (aspects of different " + focus.focusKey.replace("_", " ") + "s overlap)" : "the aspects of " + focus.focusKey.replace("_", " ") + " " + value + " in full colour, the others faint" }, box);
          b.addEventListener("click", () => { focus.focus = value; buttons.forEach(x => { x[0].className = x[1] === value ? "on" : ""; }); refresh(); });
          b.className = focus.focus === value ? "on" : "";
          buttons.push([b, value]);
        };
        groups.forEach(g => add(g, g));
        add("all", null);
      };
      const panel = new Panel2D(row, {
        title: (p.space || "tree") + " (" + t0.axes.map(axisTitle).join(", ") + ")", axes: t0.axes, root: t0.root, periodic: t0.periodic,
        layers: layers, background: null, size: size, tools: tools,
        describe: describeAspects,
        onHover: hits => setHover(new Set(hits.map(h => h.layer.aspect))),
        onLeave: () => setHover(new Set()),
        onClick: () => pin(state.pinned.size ? new Set() : new Set(state.hover)),
        overlay: (ctx, pn) => {
          if (xy) for (const L of layers) {
            const r = info.get(L.aspect);
            if (!L.visible || !r || L.weight() < 1) continue;  // only the aspects in full colour
            ctx.strokeStyle = "#111"; ctx.lineWidth = 2; ctx.setLineDash([]);
            if (r.circle) {
              const c = pn.screen(r.circle[0], r.circle[1]);
              ctx.beginPath(); ctx.arc(c[0], c[1], r.circle[2] * pn.sx, 0, 2 * Math.PI); ctx.stroke();
              ctx.strokeStyle = L.color; ctx.lineWidth = 1; ctx.stroke();
            }
            if (r.square) {
              const hs = r.square[2] / 2, a = pn.screen(r.square[0] - hs, r.square[1] + hs), b = pn.screen(r.square[0] + hs, r.square[1] - hs);
              ctx.strokeStyle = "#111"; ctx.lineWidth = 2; ctx.strokeRect(a[0], a[1], b[0] - a[0], b[1] - a[1]);
              ctx.strokeStyle = L.color; ctx.lineWidth = 1; ctx.strokeRect(a[0], a[1], b[0] - a[0], b[1] - a[1]);
            }
          }
          drawMarks(ctx, pn, t0.marks);
          drawPath(ctx, pn, sec.path === null ? null : DATA.paths[sec.path]);
        },
      });
      panel.aspectLayers = layers;
      views.push(panel);
    }
    const setVisible = (a, v) => {
      state.visible.set(a, v);
      views.forEach(pn => pn.aspectLayers.forEach(L => { if (L.aspect === a) L.visible = v; }));
      refresh();
    };
    // side column: filters, aspect table, crossings graph
    const side = el("div", { cls: "side" }, row), tools = el("div", { cls: "tools" }, side);
    const boxes = new Map();
    const show = pred => { sec.aspects.forEach(r => { const v = pred(r); boxes.get(r.aspect).checked = v; setVisible(r.aspect, v); }); };
    el("button", { text: "all" }, tools).addEventListener("click", () => show(() => true));
    el("button", { text: "none" }, tools).addEventListener("click", () => show(() => false));
    el("span", { cls: "note", text: " aspects shown" }, tools);
    const table = el("table", { cls: "legend" }, side);
    for (const r of sec.aspects) {
      const cells = r.cells.length ? r.cells.map(c => c[0] + ": " + c[1]).join("\n") : "";
      const row = legendRow(table, colour(r.aspect), "aspect " + r.aspect + "  " + (r.working_mode || "") + " " + (r.assembly_mode || "") + (r.det_sign ? "det J " + r.det_sign : "") + (r.certified === "false" ? "  not certified" : ""), true, v => setVisible(r.aspect, v), cells);
      boxes.set(r.aspect, row.box);
      legendRows.set(r.aspect, row.tr);
      row.tr.addEventListener("mouseenter", () => setHover(new Set([r.aspect])));
      row.tr.addEventListener("mouseleave", () => setHover(new Set()));
    }
    if (sec.aspects.some(r => r.circle || r.square)) el("p", { cls: "note", text: "Outlined: the largest circle and square inside each aspect (aspects.csv)." }, side);
    probes.push(() => [...active()].sort((a, b) => a - b));
    graphNodes = drawGraph(side, sec, colour, a => pin(new Set([a])), (a, b) => pin(new Set([a, b])), a => setHover(a === null ? new Set() : new Set([a])), () => pin(new Set()));
    return views;
  }

  /* The crossings graph: per assembly mode, an edge for each pair of aspects touching across one
     serial singularity. Crossing one changes one sign of the working mode, so the graph is
     bipartite by the parity of the '-' signs: even on the left, odd on the right. Click a node
     or an edge to pin it. */
  function drawGraph(host, sec, colour, onNode, onEdge, onHover, onClear) {
    const nodes = new Map();
    if (!sec.crossings.length) { el("p", { cls: "note", text: "No crossings table (aspects-adjacency.csv) or no crossing." }, host); return nodes; }
    el("p", { cls: "note", text: "Crossings graph (aspects-adjacency.csv): aspects that touch across one serial singularity. Click a node or an edge to pin it; click the background to unpin." }, host);
    const groups = [...new Set(sec.aspects.map(r => r.assembly_mode))];
    const sings = [...new Set(sec.crossings.map(c => c.singularity))];
    const parity = r => (String(r.working_mode || "").match(/-/g) || []).length % 2;
    const rows = groups.map(m => { const ms = sec.aspects.filter(r => r.assembly_mode === m); return Math.max(ms.filter(r => !parity(r)).length, ms.filter(parity).length); });
    const W = 250, ROW = 34, HEAD = 22, LEG = 18 * sings.length + 6;
    const height = LEG + rows.reduce((s, n) => s + HEAD + n * ROW + 8, 0);
    const g = svg("svg", { width: W, height: height, class: "graph", viewBox: "0 0 " + W + " " + height }, host);
    svg("rect", { x: 0, y: 0, width: W, height: height, fill: "#fff" }, g).addEventListener("click", onClear);
    const dash = name => sings.indexOf(name) % 2 ? "6,4" : "";
    const stroke = name => ["#333", "#1a6fb5", "#b5541a", "#3a8a3a"][sings.indexOf(name) % 4];
    sings.forEach((name, k) => {
      const y = 12 + 18 * k;
      svg("line", { x1: 8, y1: y, x2: 40, y2: y, stroke: stroke(name), "stroke-width": 2, "stroke-dasharray": dash(name) }, g);
      svg("text", { x: 46, y: y + 4 }, g).textContent = "across " + name + " = 0";
    });
    const where = new Map();
    let top = LEG;
    groups.forEach((m, gi) => {
      svg("text", { x: 6, y: top + 14 }, g).textContent = m ? "assembly mode " + m : "aspects";
      const ms = sec.aspects.filter(r => r.assembly_mode === m);
      for (const side of [0, 1]) {
        ms.filter(r => parity(r) === side).forEach((r, k) => where.set(r.aspect, [side ? W - 50 : 50, top + HEAD + ROW * k + ROW / 2]));
      }
      top += HEAD + rows[gi] * ROW + 8;
    });
    for (const c of sec.crossings) {
      const a = where.get(c.a), b = where.get(c.b);
      if (!a || !b) continue;
      const line = svg("line", { x1: a[0], y1: a[1], x2: b[0], y2: b[1], stroke: stroke(c.singularity), "stroke-width": 2.5, "stroke-dasharray": dash(c.singularity), class: "edge" }, g);
      svg("title", {}, line).textContent = "aspects " + c.a + " and " + c.b + " touch across " + c.singularity + " = 0";
      line.addEventListener("click", () => onEdge(c.a, c.b));
    }
    for (const r of sec.aspects) {
      const p = where.get(r.aspect);
      if (!p) continue;
      const node = svg("circle", { cx: p[0], cy: p[1], r: 12, fill: colour(r.aspect), stroke: "#444", "stroke-width": 1, class: "node" }, g);
      svg("title", {}, node).textContent = "aspect " + r.aspect + ": working mode " + r.working_mode + ", assembly mode " + r.assembly_mode;
      node.addEventListener("click", () => onNode(r.aspect));
      node.addEventListener("mouseenter", () => onHover(r.aspect));
      node.addEventListener("mouseleave", () => onHover(null));
      svg("text", { x: p[0], y: p[1] + 4, "text-anchor": "middle", fill: "#fff" }, g).textContent = String(r.aspect);
      svg("text", { x: p[0] + (p[0] < W / 2 ? -18 : 18), y: p[1] + 4, "text-anchor": p[0] < W / 2 ? "end" : "start", fill: "#333" }, g).textContent = r.working_mode || "";
      nodes.set(r.aspect, node);
    }
    return nodes;
  }

  // ------------------------------------------------------------------ main

  const trees = DATA.trees.map(decode);
  const root = document.getElementById("sections");
  for (const sec of DATA.sections) {
    const host = el("section", {}, root);
    el("h2", { text: sec.title }, host);
    if (sec.kind === "aspects") buildAspects(host, sec, trees);
    else if (sec.kind === "octree") buildOctree(host, sec, trees);
    else buildPaving(host, sec, trees);
  }
  for (const p of panels) p.render();
  FIRST.active = false;
  let cells = 0;
  FIRST.drawn.forEach(v => { cells += v; });
  const ms = performance.now() - T0, total = trees.reduce((s, t) => s + t.n, 0);
  document.getElementById("summary").textContent = DATA.trees.length + " trees, " + total + " black leaves; decoded and drawn " + cells + " leaves in " + ms.toFixed(0) + " ms";
  document.body.dataset.cells = String(cells);
  document.body.dataset.paintMs = ms.toFixed(1);
  document.body.dataset.loadMs = performance.now().toFixed(1);
  document.body.dataset.ready = "true";
  if (location.hash === "#probe") probe();

  /* Self-check for tests (page opened with #probe): point at the centre of every 2-D panel in turn
     with real mouse events, as a mouse moving from panel to panel (each left before the next is
     entered: two panels under the cursor at once would each re-highlight their own aspects on
     every frame), recording each panel's read-out and the aspects highlighted meanwhile; then
     whether panning a periodic panel by one period repaints the same image (the torus). */
  function probe() {
    const flat = panels.filter(p => p instanceof Panel2D);
    const out = { readouts: [], highlighted: [], torus: [] };
    const visit = k => {
      if (k === flat.length) return finish();
      const p = flat[k], r = p.canvas.getBoundingClientRect();
      p.canvas.dispatchEvent(new MouseEvent("mousemove", { clientX: r.left + p.m.l + p.pw / 2, clientY: r.top + p.m.t + p.ph / 2, bubbles: true }));
      frame(() => frame(() => {
        out.readouts.push(p.readout.textContent);
        out.highlighted.push(probes.map(f => f()));
        p.canvas.dispatchEvent(new MouseEvent("mouseleave"));
        visit(k + 1);
      }));
    };
    const finish = () => {
      for (const p of flat.filter(q => q.periodic[0] || q.periodic[1])) {
        p.render();
        const before = p.image.data.slice(), shift = p.root.map((r, j) => p.periodic[j] ? r[1] - r[0] : 0);
        p.vx0 += shift[0]; p.vy0 += shift[1]; p.render();
        const after = p.image.data;
        let differ = 0;
        for (let k = 0; k < after.length; k += 4) if (Math.abs(after[k] - before[k]) + Math.abs(after[k + 1] - before[k + 1]) + Math.abs(after[k + 2] - before[k + 2]) > 6) differ++;
        out.torus.push(differ / (after.length / 4));
        p.vx0 -= shift[0]; p.vy0 -= shift[1]; p.render();
      }
      document.body.dataset.probe = JSON.stringify(out);
    };
    visit(0);
  }
})();
