// Small DOM helpers shared by the pages.
import { FileEntry, FieldModel } from './api';

export function el<K extends keyof HTMLElementTagNameMap>(
  tag: K,
  attrs: Record<string, string> = {},
  ...children: (Node | string)[]
): HTMLElementTagNameMap[K] {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'text') e.textContent = v;
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}

// A labelled <select> of the files of given kinds (empty option first when `optional`).
export function fileSelect(id: string, list: FileEntry[], kinds: string[], optional = false): HTMLSelectElement {
  const s = el('select', { id });
  if (optional) s.append(el('option', { value: '', text: '(none)' }));
  for (const f of list.filter((f) => kinds.includes(f.kind))) s.append(el('option', { value: f.path, text: f.path }));
  return s;
}

export function optionsSelect(id: string, values: string[], selected = ''): HTMLSelectElement {
  const s = el('select', { id });
  for (const v of values) s.append(el('option', { value: v, text: v }));
  if (selected) s.value = selected;
  return s;
}

export function labelled(text: string, input: HTMLElement): HTMLLabelElement {
  return el('label', {}, el('span', { text }), input);
}

export function status(target: HTMLElement, message: string, error = false): void {
  target.textContent = message;
  target.className = error ? 'status error' : 'status';
}

// Top view of a field on a canvas: world (x, y) metres -> canvas pixels, y up.
export class FieldMap {
  scale = 1;
  ox = 0;
  oy = 0;
  constructor(public canvas: HTMLCanvasElement, public field: FieldModel) {
    const hl = field.length_m / 2 + field.surround_m;
    const hw = field.width_m / 2 + field.surround_m;
    this.scale = Math.min(canvas.width / (2 * hl), canvas.height / (2 * hw));
    this.ox = canvas.width / 2;
    this.oy = canvas.height / 2;
  }
  toCanvas(x: number, y: number): [number, number] {
    return [this.ox + x * this.scale, this.oy - y * this.scale];
  }
  toWorld(px: number, py: number): [number, number] {
    return [(px - this.ox) / this.scale, (this.oy - py) / this.scale];
  }
  // Surface, lines and a 1 m / 5 m scale bar.
  draw(): CanvasRenderingContext2D {
    const ctx = this.canvas.getContext('2d')!;
    const f = this.field;
    ctx.fillStyle = f.surface === 'court' ? '#b9855a' : '#2f7d32';
    ctx.fillRect(0, 0, this.canvas.width, this.canvas.height);
    ctx.strokeStyle = '#fff';
    ctx.lineWidth = Math.max(1, f.segments[0]?.width_m * this.scale || 1);
    for (const s of f.segments) {
      ctx.beginPath();
      ctx.moveTo(...this.toCanvas(s.a[0], s.a[1]));
      ctx.lineTo(...this.toCanvas(s.b[0], s.b[1]));
      ctx.stroke();
    }
    for (const a of f.arcs) {
      const [cx, cy] = this.toCanvas(a.centre[0], a.centre[1]);
      ctx.beginPath();
      ctx.arc(cx, cy, a.radius_m * this.scale, -a.end_rad, -a.start_rad);
      ctx.stroke();
    }
    // Scale bar.
    const bar_m = f.length_m > 50 ? 10 : f.length_m > 20 ? 5 : 1;
    const [x0, y0] = [10, this.canvas.height - 10];
    ctx.strokeStyle = '#fff';
    ctx.lineWidth = 3;
    ctx.beginPath();
    ctx.moveTo(x0, y0);
    ctx.lineTo(x0 + bar_m * this.scale, y0);
    ctx.stroke();
    ctx.fillStyle = '#fff';
    ctx.font = '12px sans-serif';
    ctx.fillText(`${bar_m} m`, x0, y0 - 5);
    ctx.fillText('x →', this.canvas.width - 30, this.canvas.height - 8);
    return ctx;
  }
}

// Colour of a value 0..1 on a blue -> green -> yellow -> red scale (time colouring).
export function rampColour(t: number): [number, number, number] {
  const stops: [number, number, number][] = [
    [0.23, 0.3, 0.75],
    [0.2, 0.7, 0.6],
    [0.95, 0.85, 0.2],
    [0.85, 0.2, 0.15],
  ];
  const x = Math.min(Math.max(t, 0), 1) * (stops.length - 1);
  const i = Math.min(Math.floor(x), stops.length - 2);
  const f = x - i;
  return [0, 1, 2].map((k) => stops[i][k] + f * (stops[i + 1][k] - stops[i][k])) as [number, number, number];
}
