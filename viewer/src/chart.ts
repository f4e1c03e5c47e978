// Per-frame plots under the 3D view (layers.json "frames"): energy, contacts, budget spent, one
// lane each with its own y-range, a shared time axis and a cursor at the current time. Clicking
// or dragging in the chart scrubs.
import type { LayersFile } from './data';

interface Series {
  label: string;
  color: string;
  values: number[];
  dashed?: boolean;
}
interface Lane {
  title: string;
  unit: string;
  series: Series[];
}

export class Chart {
  private readonly ctx: CanvasRenderingContext2D;
  private lanes: Lane[] = [];
  private times: number[] = [];
  private cursor = 0;

  constructor(private readonly canvas: HTMLCanvasElement, onScrub: (time: number) => void) {
    this.ctx = canvas.getContext('2d')!;
    new ResizeObserver(() => this.draw()).observe(canvas);
    let dragging = false;
    const scrub = (e: PointerEvent) => {
      if (this.times.length < 2) return;
      const r = canvas.getBoundingClientRect();
      const u = (e.clientX - r.left - this.plotLeft()) / Math.max(1, r.width - this.plotLeft() - 8);
      const t0 = this.times[0], t1 = this.times[this.times.length - 1];
      onScrub(t0 + Math.min(1, Math.max(0, u)) * (t1 - t0));
    };
    canvas.addEventListener('pointerdown', (e) => {
      dragging = true;
      canvas.setPointerCapture(e.pointerId);
      scrub(e);
    });
    canvas.addEventListener('pointermove', (e) => dragging && scrub(e));
    canvas.addEventListener('pointerup', () => (dragging = false));
  }

  /** Sets the data; returns false if there is nothing to plot (e.g. a bake export). */
  setData(layers: LayersFile | null): boolean {
    const f = layers?.frames;
    this.lanes = [];
    this.times = f?.time ?? [];
    if (!f || this.times.length === 0) {
      this.draw();
      return false;
    }
    const energy: Series[] = [];
    if (f.kinetic_energy) energy.push({ label: 'kinetic', color: '#ff9f43', values: f.kinetic_energy });
    if (f.potential_energy) energy.push({ label: 'potential', color: '#54a0ff', values: f.potential_energy });
    if (f.total_energy) energy.push({ label: 'total', color: '#e8e8e8', values: f.total_energy });
    if (energy.length) this.lanes.push({ title: 'energy', unit: 'J', series: energy });
    if (f.contacts) this.lanes.push({ title: 'contacts', unit: '', series: [{ label: 'contacts', color: '#ff5e57', values: f.contacts }] });
    const budget: Series[] = [];
    if (f.tests_spent) budget.push({ label: 'spent', color: '#1dd1a1', values: f.tests_spent });
    if (f.tests_budget && f.tests_budget.some((b) => b > 0))
      budget.push({ label: 'budget', color: '#c8d6e5', values: f.tests_budget, dashed: true });
    if (budget.length) this.lanes.push({ title: 'tests', unit: '', series: budget });
    this.draw();
    return this.lanes.length > 0;
  }

  setCursor(time: number): void {
    this.cursor = time;
    this.draw();
  }

  private plotLeft(): number {
    return 64;
  }

  draw(): void {
    const dpr = window.devicePixelRatio || 1;
    const w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    if (w === 0 || h === 0) return;
    if (this.canvas.width !== Math.round(w * dpr) || this.canvas.height !== Math.round(h * dpr)) {
      this.canvas.width = Math.round(w * dpr);
      this.canvas.height = Math.round(h * dpr);
    }
    const ctx = this.ctx;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, w, h);
    if (this.lanes.length === 0 || this.times.length === 0) return;
    const left = this.plotLeft(), right = w - 8, top = 4, bottom = h - 14;
    const laneH = (bottom - top) / this.lanes.length;
    const t0 = this.times[0], t1 = this.times[this.times.length - 1];
    const xOf = (t: number) => left + ((t - t0) / Math.max(1e-12, t1 - t0)) * (right - left);
    ctx.font = '10px system-ui, sans-serif';
    this.lanes.forEach((lane, k) => {
      const y0 = top + k * laneH + 3, y1 = top + (k + 1) * laneH - 3;
      let lo = Infinity, hi = -Infinity;
      for (const s of lane.series) for (const v of s.values) if (Number.isFinite(v)) (lo = Math.min(lo, v)), (hi = Math.max(hi, v));
      if (!Number.isFinite(lo)) (lo = 0), (hi = 1);
      if (lane.title !== 'energy') lo = Math.min(lo, 0);
      if (hi - lo < 1e-12) hi = lo + 1;
      const yOf = (v: number) => y1 - ((v - lo) / (hi - lo)) * (y1 - y0);
      ctx.fillStyle = 'rgba(255,255,255,0.04)';
      ctx.fillRect(left, y0, right - left, y1 - y0);
      ctx.fillStyle = '#9aa4b2';
      ctx.textBaseline = 'top';
      ctx.fillText(lane.title + (lane.unit ? ` [${lane.unit}]` : ''), 4, y0);
      ctx.fillText(formatNumber(hi), 4, y0 + 11);
      ctx.textBaseline = 'bottom';
      ctx.fillText(formatNumber(lo), 4, y1);
      for (const s of lane.series) {
        ctx.strokeStyle = s.color;
        ctx.lineWidth = 1.25;
        ctx.setLineDash(s.dashed ? [4, 3] : []);
        ctx.beginPath();
        const n = Math.min(s.values.length, this.times.length);
        for (let i = 0; i < n; ++i) {
          const x = xOf(this.times[i]), y = yOf(s.values[i]);
          if (i === 0) ctx.moveTo(x, y);
          else ctx.lineTo(x, y);
        }
        ctx.stroke();
      }
      ctx.setLineDash([]);
      // Legend, right-aligned inside the lane.
      let lx = right - 4;
      ctx.textBaseline = 'top';
      ctx.textAlign = 'right';
      for (const s of [...lane.series].reverse()) {
        ctx.fillStyle = s.color;
        ctx.fillText(s.label, lx, y0 + 1);
        lx -= ctx.measureText(s.label).width + 10;
      }
      ctx.textAlign = 'left';
    });
    // Time axis labels and the cursor.
    ctx.fillStyle = '#9aa4b2';
    ctx.textBaseline = 'bottom';
    ctx.fillText(`${t0.toFixed(2)} s`, left, h);
    ctx.textAlign = 'right';
    ctx.fillText(`${t1.toFixed(2)} s`, right, h);
    ctx.textAlign = 'left';
    const cx = xOf(Math.min(Math.max(this.cursor, t0), t1));
    ctx.strokeStyle = '#ffffff';
    ctx.lineWidth = 1;
    ctx.beginPath();
    ctx.moveTo(cx, top);
    ctx.lineTo(cx, bottom);
    ctx.stroke();
  }
}

function formatNumber(v: number): string {
  const a = Math.abs(v);
  if (a !== 0 && (a >= 1e5 || a < 1e-2)) return v.toExponential(1);
  return Number.isInteger(v) ? String(v) : v.toFixed(a >= 100 ? 0 : 2);
}
