// Calls to the studio server's JSON API (src/fieldvision/web/studio_api.h). The session token,
// when the server needs one (non-loopback --host), comes from the page's ?token= and is sent as
// the X-Studio-Token header.
export const token = new URLSearchParams(location.search).get('token') ?? '';

export class ApiError extends Error {
  constructor(public status: number, message: string) {
    super(message);
  }
}

function headers(json: boolean): HeadersInit {
  const h: Record<string, string> = {};
  if (token) h['X-Studio-Token'] = token;
  if (json) h['Content-Type'] = 'application/json';
  return h;
}

async function check(res: Response): Promise<Response> {
  if (res.ok) return res;
  let message = `${res.status} ${res.statusText}`;
  try {
    message = (await res.json()).error ?? message;
  } catch {
    /* not JSON */
  }
  throw new ApiError(res.status, message);
}

export function url(path: string, params: Record<string, string | number> = {}): string {
  const q = new URLSearchParams();
  for (const [k, v] of Object.entries(params)) q.set(k, String(v));
  if (token) q.set('token', token);
  const s = q.toString();
  return s ? `${path}?${s}` : path;
}

export async function get<T>(path: string, params: Record<string, string | number> = {}): Promise<T> {
  return (await check(await fetch(url(path, params), { headers: headers(false) }))).json();
}

export async function post<T>(path: string, body: unknown): Promise<T> {
  const res = await fetch(url(path), { method: 'POST', headers: headers(true), body: JSON.stringify(body) });
  return (await check(res)).json();
}

// A save that asks before replacing a file: the server refuses an existing output (409); the
// user is asked, and only a yes sends the save again with replace.
export async function postSave<T>(path: string, body: Record<string, unknown>): Promise<T> {
  try {
    return await post<T>(path, body);
  } catch (e) {
    if (!(e instanceof ApiError) || e.status !== 409) throw e;
    const name = String(body.out ?? body.points_out ?? 'the file');
    if (!confirm(`${name} exists. Replace it?`)) throw new ApiError(409, `${name} exists: not replaced (choose another name)`);
    return post<T>(path, { ...body, replace: true });
  }
}

// A frame of a video as an image element (PNG from /api/frame).
export function loadFrame(video: string, frame: number): Promise<HTMLImageElement> {
  return new Promise((resolve, reject) => {
    const img = new Image();
    img.onload = () => resolve(img);
    img.onerror = () =>
      fetch(url('/api/frame', { path: video, frame }))
        .then(check)
        .then(() => reject(new Error('frame cannot be shown')), reject);
    img.src = url('/api/frame', { path: video, frame });
  });
}

export interface FileEntry {
  path: string;
  size: number;
  kind: 'video' | 'images' | 'image' | 'camera' | 'csv' | 'json' | 'other';
}

export interface FieldModel {
  name: string;
  length_m: number;
  width_m: number;
  surround_m: number;
  surface: string;
  segments: { name: string; a: number[]; b: number[]; width_m: number }[];
  arcs: { name: string; centre: number[]; radius_m: number; start_rad: number; end_rad: number }[];
  keypoints: { name: string; position_m: number[] }[];
}

export interface CameraJson {
  name: string;
  width: number;
  height: number;
  fx: number;
  fy: number;
  cx: number;
  cy: number;
  has_pose: boolean;
  position_m?: number[];
  cam_from_world_rotation?: number[];
  tvec?: number[];
  // The image's border through the lens model, normalized (x/z, y/z), round from the top-left.
  image_outline_normalized?: number[][];
}

export async function files(): Promise<FileEntry[]> {
  return get<FileEntry[]>('/api/files');
}

export async function info(): Promise<{ root: string; fields: string[] }> {
  return get('/api/info');
}
