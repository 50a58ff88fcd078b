// Zones: draw named polygons on the field map (click the corners, then "Close zone") for zone
// time and alerts (`fieldvision stats --zones zones.json`); load and save the zones file.
import * as api from './api';
import { el, fileSelect, optionsSelect, labelled, status, FieldMap } from './ui';

export interface Zone {
  name: string;
  polygon: number[][];
}

// Draws zones on a field map, each in its own colour with its name.
export function drawZones(ctx: CanvasRenderingContext2D, fmap: FieldMap, zones: Zone[]): void {
  zones.forEach((z, i) => {
    const colour = `hsla(${(i * 97 + 30) % 360}, 90%, 60%,`;
    ctx.beginPath();
    z.polygon.forEach(([x, y], k) => (k ? ctx.lineTo(...fmap.toCanvas(x, y)) : ctx.moveTo(...fmap.toCanvas(x, y))));
    ctx.closePath();
    ctx.fillStyle = `${colour} 0.25)`;
    ctx.fill();
    ctx.strokeStyle = `${colour} 1)`;
    ctx.lineWidth = 2;
    ctx.stroke();
    const [cx, cy] = z.polygon.reduce(([a, b], [x, y]) => [a + x / z.polygon.length, b + y / z.polygon.length], [0, 0]);
    ctx.fillStyle = '#fff';
    ctx.font = 'bold 13px sans-serif';
    ctx.fillText(z.name, ...fmap.toCanvas(cx, cy));
  });
}

export async function zonesPage(root: HTMLElement): Promise<void> {
  const [list, info] = await Promise.all([api.files(), api.info()]);
  const field = optionsSelect('zn-field', info.fields, 'robocup-msl');
  const existing = fileSelect('zn-file', list, ['json'], true);
  const open = el('button', { id: 'zn-open', text: 'Open' });
  const name = el('input', { id: 'zn-name', value: 'zone1' });
  const close = el('button', { id: 'zn-close', text: 'Close zone' });
  const undo = el('button', { id: 'zn-undo', text: 'Remove last corner' });
  const out = el('input', { id: 'zn-out', value: 'zones.json' });
  const save = el('button', { id: 'zn-save', text: 'Save zones file' });
  const map = el('canvas', { id: 'zn-map', width: '900', height: '600', class: 'frame' });
  const zoneList = el('ul', { id: 'zn-list' });
  const msg = el('div', { id: 'zn-status', class: 'status' });
  const pointer = el('div', { id: 'zn-pointer', class: 'hint' });
  root.replaceChildren(
    el('section', { class: 'controls' }, labelled('Field', field), labelled('Zones file', existing), open),
    el('div', { class: 'workspace' },
      el('div', { class: 'main-view' }, map, pointer, msg),
      el('div', { class: 'side' }, el('p', { class: 'hint', text: 'Click the corners of a zone on the map, name it, then close it.' }),
        labelled('Name', name), close, undo, el('h3', { text: 'Zones' }), zoneList, el('p', {}, labelled('Save as', out)), save)),
  );

  let fmap: FieldMap | null = null;
  let zones: Zone[] = [];
  let corners: number[][] = [];

  function draw() {
    if (!fmap) return;
    const ctx = fmap.draw();
    drawZones(ctx, fmap, zones);
    ctx.strokeStyle = '#ff0';
    ctx.fillStyle = '#ff0';
    ctx.beginPath();
    corners.forEach(([x, y], k) => (k ? ctx.lineTo(...fmap!.toCanvas(x, y)) : ctx.moveTo(...fmap!.toCanvas(x, y))));
    ctx.stroke();
    for (const [x, y] of corners) {
      const [px, py] = fmap.toCanvas(x, y);
      ctx.fillRect(px - 3, py - 3, 6, 6);
    }
    zoneList.replaceChildren(...zones.map((z, i) => {
      const del = el('button', { text: '×', title: 'delete' });
      del.onclick = () => {
        zones.splice(i, 1);
        draw();
      };
      return el('li', { 'data-zone': z.name }, `${z.name}: ${z.polygon.length} corners `, del);
    }));
  }
  const toWorld = (e: PointerEvent): number[] => {
    const s = map.width / map.clientWidth;
    const [x, y] = fmap!.toWorld(e.offsetX * s, e.offsetY * s);
    return [Math.round(x * 100) / 100, Math.round(y * 100) / 100];
  };
  async function loadField() {
    fmap = new FieldMap(map, await api.get<api.FieldModel>('/api/field', { name: field.value }));
    draw();
  }
  map.addEventListener('pointerdown', (e) => {
    if (!fmap) return;
    corners.push(toWorld(e));
    draw();
  });
  map.addEventListener('pointermove', (e) => {
    if (!fmap) return;
    const [x, y] = toWorld(e);
    pointer.textContent = `x ${x.toFixed(2)} m, y ${y.toFixed(2)} m`;
  });
  close.onclick = () => {
    if (corners.length < 3) return status(msg, 'a zone needs 3 or more corners', true);
    zones.push({ name: name.value || `zone${zones.length + 1}`, polygon: corners });
    corners = [];
    name.value = `zone${zones.length + 1}`;
    draw();
  };
  undo.onclick = () => {
    corners.pop();
    draw();
  };
  field.onchange = () => void loadField();
  open.onclick = async () => {
    try {
      zones = await api.get<Zone[]>('/api/zones', { path: existing.value });
      draw();
      status(msg, `${zones.length} zones from ${existing.value}`);
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
  save.onclick = async () => {
    try {
      const r = await api.postSave<{ wrote: string[] }>('/api/zones/save', { zones, out: out.value });
      status(msg, `wrote ${r.wrote.join(', ')}`);
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
  await loadField();
  map.dataset.ready = '1';
}
