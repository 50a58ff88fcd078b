// The studio's pages, one per hash (#calibrate, #colour, #view3d, #players, #zones, #jobs; #bench3d
// is the 3D view's benchmark), and the live status
// line fed by the server's Server-Sent Events (/api/events).
import './style.css';
import { url } from './api';

// Each page is its own chunk, loaded when opened (three.js and uPlot only for the 3D view).
const pages: Record<string, (root: HTMLElement) => Promise<void>> = {
  calibrate: async (root) => (await import('./calibrate')).calibratePage(root),
  colour: async (root) => (await import('./colour')).colourPage(root),
  view3d: async (root) => (await import('./view3d')).view3dPage(root),
  bench3d: async (root) => (await import('./view3d')).view3dPage(root, { bench: true }),
  players: async (root) => (await import('./players')).playersPage(root),
  zones: async (root) => (await import('./zones')).zonesPage(root),
  jobs: async (root) => (await import('./jobs')).jobsPage(root),
};

async function route(): Promise<void> {
  const name = location.hash.slice(1) || 'calibrate';
  const root = document.getElementById('page')!;
  for (const a of document.querySelectorAll<HTMLAnchorElement>('#nav a')) {
    a.classList.toggle('active', a.hash === `#${name}`);
  }
  const page = pages[name] ?? pages.calibrate;
  root.dataset.page = name;
  root.dataset.ready = '';
  try {
    await page(root);
  } catch (e) {
    root.textContent = `cannot open the page: ${(e as Error).message}`;
  }
  root.dataset.ready = '1';
}

const live = document.getElementById('live')!;
// Pages listen for the server's events as 'studio-event' on the window ({type, data}).
const relay = (type: string) => (e: Event) => {
  const data = JSON.parse((e as MessageEvent).data);
  window.dispatchEvent(new CustomEvent('studio-event', { detail: { type, data } }));
  return data;
};
// One stream per visible tab: a browser gives a server six connections, and six tabs each
// holding a stream left none for the pages' requests. A hidden tab closes its stream and, shown
// again, resumes after the last event it had (the server replays what it still keeps).
let events: EventSource | null = null;
let lastId = '';
let unreachable = 0;
function connect(): void {
  const es = new EventSource(url('/api/events', lastId ? { since: lastId } : {}));
  const seen = (e: Event) => {
    const id = (e as MessageEvent).lastEventId;
    if (id) lastId = id;
  };
  es.addEventListener('hello', () => {
    clearTimeout(unreachable);
    unreachable = 0;
    live.textContent = 'live';
  });
  es.addEventListener('saved', (e) => {
    seen(e);
    live.textContent = `saved ${relay('saved')(e).path}`;
  });
  es.addEventListener('job', (e) => {
    seen(e);
    const d = relay('job')(e);
    live.textContent = `job ${d.id} ${d.command}: ${d.state}`;
  });
  // Positions from a fusion node (live mode) and the live feed's state go to the pages only.
  es.addEventListener('ball', (e) => (seen(e), relay('ball')(e)));
  es.addEventListener('live', (e) => (seen(e), relay('live')(e)));
  // The server ends a stream every minute and the browser reconnects at once: only a stream
  // not back within 5 s means the server is gone.
  es.onerror = () => {
    if (!unreachable) {
      unreachable = window.setTimeout(() => (live.textContent = 'server not reachable'), 5000);
    }
  };
  events = es;
}
document.addEventListener('visibilitychange', () => {
  if (document.hidden) {
    events?.close();
    events = null;
    clearTimeout(unreachable);
    unreachable = 0;
  } else if (!events) {
    connect();
  }
});
if (!document.hidden) connect();

window.addEventListener('hashchange', () => void route());
void route();
