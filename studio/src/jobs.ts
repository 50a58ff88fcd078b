// Jobs: run ball, trajectory, players, stats, plan, detect or synth on files of the folder; the
// server runs each as a child process (web/jobs.h) and streams its progress line and output as
// "job" events, shown here live; a running job can be cancelled.
import * as api from './api';
import { el, optionsSelect, labelled, status } from './ui';

interface Job {
  id: number;
  command: string;
  args: string[];
  state: string;
  exit_code: number;
  progress: string;
  output: string;
  elapsed_s: number;
}

const examples: Record<string, string> = {
  ball: '--camera scene/cam1.yaml --video scene/cam1.avi --camera scene/cam2.yaml --video scene/cam2.avi --out ball.csv',
  trajectory: '--in ball.csv --out flights.json',
  players: '--camera scene/cam1.yaml --video scene/cam1.avi --out TRACKS.csv',
  stats: '--tracks TRACKS.csv --field robocup-msl --out stats',
  plan: '--camera scene/cam1.yaml --camera scene/cam2.yaml --field robocup-msl --out plan',
  detect: '--camera scene/cam1.yaml --video scene/cam1.avi --out det.csv',
  synth: '--preset kick --frames 60 --out scene2',
};

// The arguments as a shell splits them: "a b" or 'a b' is one argument (a path with spaces).
export function splitArgs(text: string): string[] {
  const out: string[] = [];
  const re = /"([^"]*)"|'([^']*)'|(\S+)/g;
  for (let m = re.exec(text); m; m = re.exec(text)) out.push(m[1] ?? m[2] ?? m[3]);
  return out;
}

export async function jobsPage(root: HTMLElement): Promise<void> {
  const command = optionsSelect('jb-command', Object.keys(examples), 'ball');
  const args = el('input', { id: 'jb-args', value: examples.ball, size: '90' });
  // An existing output (an earlier run's ball.csv) is written over only when asked.
  const replace = el('input', { id: 'jb-replace', type: 'checkbox' }) as HTMLInputElement;
  const start = el('button', { id: 'jb-start', text: 'Start' });
  const msg = el('div', { id: 'jb-status', class: 'status' });
  const table = el('table', { id: 'jb-list' });
  root.replaceChildren(
    el('section', { class: 'controls' }, labelled('Command', command), labelled('Arguments (paths inside the folder; quote a path with spaces)', args),
      el('label', {}, replace, 'Replace existing outputs'), start),
    msg, table,
  );
  command.onchange = () => (args.value = examples[command.value]);

  const jobs = new Map<number, Job>();
  // A job's news in any order (the start's reply can come after the event of its end): an ended
  // job never goes back to running.
  function update(j: Job) {
    const known = jobs.get(j.id);
    if (known && known.state !== 'running' && j.state === 'running') return;
    jobs.set(j.id, j);
  }
  function draw() {
    table.replaceChildren(
      el('tr', {}, ...['id', 'command', 'state', 'time', 'progress / output', ''].map((h) => el('th', { text: h }))),
      ...[...jobs.values()].sort((a, b) => b.id - a.id).map((j) => {
        const cancel = el('button', { text: 'Cancel', 'data-cancel': String(j.id) });
        cancel.onclick = async () => {
          try {
            await api.post('/api/jobs/cancel', { id: j.id });
          } catch (e) {
            status(msg, (e as Error).message, true);
          }
        };
        const tail = j.state === 'running' ? j.progress : j.output.trim().split('\n').slice(-3).join(' | ');
        return el('tr', { 'data-job': String(j.id), 'data-state': j.state },
          el('td', { text: String(j.id) }), el('td', { text: `${j.command} ${j.args.join(' ')}`, style: 'text-align:left' }),
          el('td', { text: j.state === 'failed' ? `failed (exit ${j.exit_code})` : j.state }),
          el('td', { text: `${j.elapsed_s.toFixed(1)} s` }), el('td', { text: tail, style: 'text-align:left; max-width:40em' }),
          el('td', {}, ...(j.state === 'running' ? [cancel] : [])));
      }),
    );
  }
  const onEvent = (e: Event) => {
    const d = (e as CustomEvent).detail;
    if (d.type !== 'job' || !root.isConnected) return;
    update(d.data);
    draw();
  };
  window.addEventListener('studio-event', onEvent);
  start.onclick = async () => {
    try {
      const j = await api.post<Job>('/api/jobs', {
        command: command.value, args: splitArgs(args.value), replace: replace.checked,
      });
      update(j);
      draw();
      status(msg, `started job ${j.id}`);
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
  for (const j of await api.get<Job[]>('/api/jobs')) update(j);
  draw();
}
