// The SAFECASS live viewer page: draws coordinators → components → machines from the server's
// "hello", keeps them current from its "update" pushes, shows the cause of a clicked state
// ("explain") and, when the viewer was started with --allow-write, sends generate / inject /
// reset requests carrying the token. The protocol is documented in
// tools/viewer/include/safecass/viewer/protocol.hpp.

type StateName = 'Normal' | 'Warning' | 'Error';

interface MachineView {
  address: string;
  kind: 'framework' | 'application' | 'provided' | 'required' | 'service';
  name: string;
  state: StateName;
  outstanding: string;
}

interface ComponentView {
  name: string;
  address: string;
  state: StateName;
  outstanding: string;
  machines: MachineView[];
}

interface CoordinatorView {
  name: string;
  address: string;
  state: StateName;
  /** '' while current; for a live coordinator 'connecting', 'unreachable' or 'lost'. */
  status?: string;
  components: ComponentView[];
}

interface SystemView {
  system: string;
  description: string;
  t: number;
  running: boolean;
  state: StateName;
  coordinators: CoordinatorView[];
}

/** One record of the observer stream (record_to_json's format). */
interface HistoryRecord {
  seq?: number;
  t?: number;
  kind: string;
  outcome?: string;
  component?: string;
  machine?: string;
  event?: string;
  from?: StateName;
  to?: StateName;
  root?: { event: string; origin: string };
  coordinator?: string;
  text?: string;
  dropped?: number;
}

interface Condition {
  machine: string;
  event: string;
  level: StateName;
  severity: number;
  mirror: boolean;
  outstanding: boolean;
  count: number;
  first: number;
  last: number;
  root_event: string;
  root_origin: string;
  root_t: number;
  hazard?: string;
  filter?: string;
  signal?: string;
  value?: number;
  sample_t?: number;
  injected?: boolean;
  path: string[];
}

interface Hello { type: 'hello'; write: boolean; max_message: number; view: SystemView; recent: HistoryRecord[] }
interface Update { type: 'update'; t: number; running: boolean; states: Record<string, [StateName, string]>; records: HistoryRecord[] }
interface TimeMessage { type: 'time'; t: number; running: boolean }
interface Reply {
  type: 'reply';
  id?: number;
  op: string;
  text?: string;
  address?: string;
  state?: StateName;
  outstanding?: string;
  conditions?: Condition[];
  view?: SystemView;
}
interface ErrorReply { type: 'error'; id?: number; op?: string; error: string }
type ServerMessage = Hello | Update | TimeMessage | Reply | ErrorReply;

const kMaxTransitions = 200;
const kWriteOps = new Set(['generate', 'broadcast', 'inject', 'reset']);

function byId<T extends HTMLElement>(id: string): T {
  const el = document.getElementById(id);
  if (el === null) throw new Error(`the page has no element #${id}`);
  return el as T;
}

function element(tag: string, className: string, text?: string): HTMLElement {
  const el = document.createElement(tag);
  if (className !== '') el.className = className;
  if (text !== undefined) el.textContent = text;
  return el;
}

function seconds(t: number | undefined): string {
  return t === undefined ? '–' : t.toFixed(3);
}

class Viewer {
  private socket: WebSocket | null = null;
  private nodes = new Map<string, HTMLElement[]>();
  private selected = '';
  private nextId = 1;
  private pending = new Map<number, string>();
  private retryMs = 250;
  private token = '';

  start(): void {
    // A token passed in the URL fragment (#token=...) is taken and removed from the address bar.
    const match = /(?:^#|&)token=([0-9A-Za-z]+)/.exec(location.hash);
    if (match !== null) {
      this.token = match[1];
      byId<HTMLInputElement>('token').value = this.token;
      history.replaceState(null, '', location.pathname + location.search);
    }
    document.addEventListener('click', (e) => this.onClick(e));
    document.addEventListener('keydown', (e) => {
      if ((e.key === 'Enter' || e.key === ' ') && e.target instanceof HTMLElement && e.target.dataset.address !== undefined) {
        e.preventDefault();
        this.select(e.target.dataset.address);
      }
    });
    byId<HTMLFormElement>('generate-form').addEventListener('submit', (e) => {
      e.preventDefault();
      this.write({ op: 'generate', event: this.field('generate-event'), target: this.field('generate-target') });
    });
    byId<HTMLFormElement>('inject-form').addEventListener('submit', (e) => {
      e.preventDefault();
      const samples = this.parseSamples(this.field('inject-samples'));
      if (samples === null) {
        this.showResult(false, 'samples: numbers, samples separated by ";" (e.g. "50; 50" or "1 2 3; 4 5 6")');
        return;
      }
      const kind = byId<HTMLSelectElement>('inject-kind').value === 'signal' ? 'signal' : 'filter';
      this.write({ op: 'inject', [kind]: this.field('inject-target'), samples });
    });
    byId<HTMLFormElement>('reset-form').addEventListener('submit', (e) => {
      e.preventDefault();
      const reason = this.field('reset-reason');
      this.write(reason === '' ? { op: 'reset', target: this.field('reset-target') }
                               : { op: 'reset', target: this.field('reset-target'), reason });
    });
    this.connect();
  }

  private field(id: string): string {
    return byId<HTMLInputElement>(id).value.trim();
  }

  private parseSamples(text: string): number[][] | null {
    const samples: number[][] = [];
    for (const part of text.split(';')) {
      const words = part.trim().split(/[\s,]+/).filter((w) => w !== '');
      if (words.length === 0) continue;
      const values = words.map(Number);
      if (values.some((v) => !Number.isFinite(v))) return null;
      samples.push(values);
    }
    return samples.length === 0 ? null : samples;
  }

  private connect(): void {
    const status = byId('connection');
    const socket = new WebSocket(`ws://${location.host}/ws`);
    this.socket = socket;
    socket.addEventListener('open', () => {
      this.retryMs = 250;
      status.textContent = 'live';
      status.className = 'connection online';
    });
    socket.addEventListener('message', (e) => {
      if (typeof e.data !== 'string') return;
      let message: ServerMessage;
      try {
        message = JSON.parse(e.data) as ServerMessage;
      } catch {
        return;
      }
      this.onMessage(message);
    });
    socket.addEventListener('close', () => {
      status.textContent = 'disconnected: retrying…';
      status.className = 'connection offline';
      this.socket = null;
      window.setTimeout(() => this.connect(), this.retryMs);
      this.retryMs = Math.min(this.retryMs * 2, 5000);
    });
  }

  private send(request: Record<string, unknown>): void {
    if (this.socket === null || this.socket.readyState !== WebSocket.OPEN) {
      this.showResult(false, 'not connected to the viewer');
      return;
    }
    const id = this.nextId++;
    this.pending.set(id, String(request.op));
    this.socket.send(JSON.stringify({ id, ...request }));
  }

  private write(request: Record<string, unknown>): void {
    const token = byId<HTMLInputElement>('token').value.trim();
    this.send(token === '' ? request : { ...request, token });
  }

  private onMessage(m: ServerMessage): void {
    switch (m.type) {
      case 'hello': return this.onHello(m);
      case 'update': return this.onUpdate(m);
      case 'time': return this.setClock(m.t, m.running);
      case 'reply': return this.onReply(m);
      case 'error': return this.onError(m);
    }
  }

  private onHello(m: Hello): void {
    this.render(m.view);
    byId('write-panel').hidden = !m.write;
    const list = byId('transitions');
    list.replaceChildren();
    for (const r of m.recent) this.addTransition(r);
    if (this.selected !== '') this.select(this.selected);
  }

  private onUpdate(m: Update): void {
    this.setClock(m.t, m.running);
    let selectedChanged = false;
    // A state the page has not drawn (a live coordinator now answers with another shape): redraw.
    if (Object.keys(m.states).some((address) => !this.nodes.has(address))) this.send({ op: 'view' });
    for (const [address, [state, outstanding]] of Object.entries(m.states)) {
      this.setState(address, state, outstanding);
      if (address === this.selected) selectedChanged = true;
    }
    for (const r of m.records) this.addTransition(r);
    if (selectedChanged) this.select(this.selected);
  }

  private onReply(m: Reply): void {
    const op = m.id !== undefined ? this.pending.get(m.id) ?? m.op : m.op;
    if (m.id !== undefined) this.pending.delete(m.id);
    if (op === 'explain' && m.address !== undefined && m.address === this.selected) {
      this.showCause(m.address, m.state ?? 'Normal', m.conditions ?? []);
    } else if (op === 'view' && m.view !== undefined) {
      this.render(m.view);
    } else if (kWriteOps.has(op)) {
      this.showResult(true, m.text ?? 'done');
    }
  }

  private onError(m: ErrorReply): void {
    const op = m.id !== undefined ? this.pending.get(m.id) ?? m.op ?? '' : m.op ?? '';
    if (m.id !== undefined) this.pending.delete(m.id);
    if (op === 'explain') {
      byId('cause').replaceChildren(element('p', 'result error', m.error));
    } else {
      this.showResult(false, m.error);
    }
  }

  private showResult(ok: boolean, text: string): void {
    const result = byId('write-result');
    result.textContent = text;
    result.className = ok ? 'result ok' : 'result error';
  }

  private setClock(t: number, running: boolean): void {
    byId('clock').textContent = `t = ${seconds(t)} s${running ? '' : ' (no scenario steps left: the system stays up)'}`;
  }

  private stateNode(address: string, state: StateName, outstanding: string, kind: string, label: string): HTMLElement {
    const el = element('span', `state state-${state}`);
    el.dataset.address = address;
    el.dataset.state = state;
    el.tabIndex = 0;
    el.setAttribute('role', 'button');
    if (kind !== '') el.append(element('span', 'kind', kind));
    el.append(element('span', 'label', label));
    el.append(element('span', 'event', outstanding));
    el.title = `${address}: ${state}${outstanding !== '' ? ' (' + outstanding + ')' : ''}`;
    const list = this.nodes.get(address);
    if (list === undefined) this.nodes.set(address, [el]); else list.push(el);
    return el;
  }

  private render(v: SystemView): void {
    this.nodes.clear();
    byId('system').textContent = v.system;
    byId('description').textContent = v.description;
    const badge = byId('system-state');
    this.nodes.set('SYSTEM', [badge]);
    this.setState('SYSTEM', v.state, '');
    this.setClock(v.t, v.running);
    const model = byId('model');
    model.replaceChildren();
    for (const co of v.coordinators) {
      const box = element('section', 'coordinator');
      box.dataset.coordinator = co.name;
      const head = element('h2', '');
      head.append(element('span', '', 'coordinator'), this.stateNode(co.address, co.state, co.status ?? '', '', co.name));
      box.append(head);
      for (const c of co.components) {
        const row = element('div', 'component');
        row.dataset.component = c.name;
        const name = this.stateNode(c.address, c.state, c.outstanding, '', c.name);
        name.classList.add('component-name');
        const machines = element('div', 'machines');
        for (const m of c.machines) {
          // s_F and s_A by name; interfaces as "P ForceData", "R ForceData", "S Command".
          const kind = m.kind === 'framework' || m.kind === 'application' ? '' : m.kind[0].toUpperCase();
          machines.append(this.stateNode(m.address, m.state, m.outstanding, kind, m.name));
        }
        row.append(name, machines);
        box.append(row);
      }
      model.append(box);
    }
    if (this.selected !== '') this.markSelected();
  }

  private setState(address: string, state: StateName, outstanding: string): void {
    for (const el of this.nodes.get(address) ?? []) {
      const before = el.classList.contains(`state-${state}`);
      el.classList.remove('state-Normal', 'state-Warning', 'state-Error');
      el.classList.add(`state-${state}`);
      el.dataset.state = state;
      const event = el.querySelector('.event');
      if (event !== null) event.textContent = outstanding;
      el.title = `${address}: ${state}${outstanding !== '' ? ' (' + outstanding + ')' : ''}`;
      if (address === 'SYSTEM') el.textContent = `SYSTEM ${state}`;
      if (!before) {
        el.classList.remove('flash');
        void el.offsetWidth;  // restart the animation
        el.classList.add('flash');
      }
    }
  }

  private addTransition(r: HistoryRecord): void {
    const list = byId('transitions');
    const item = element('li', `kind-${r.kind}`);
    item.append(element('span', 't', seconds(r.t)));
    const where = r.machine ?? r.component ?? r.coordinator ?? '';
    let text: string;
    switch (r.kind) {
      case 'transition':
      case 'component-transition':
        text = `${r.from} → ${r.to}${r.event !== undefined && r.event !== '' ? ' ' + r.event : ''}`;
        const own = r.root !== undefined && (r.root.origin === r.machine || (r.machine === undefined && r.root.origin.startsWith(`${r.component ?? ''}.`)));
        if (r.root !== undefined && !own) text += ` ← ${r.root.origin}:${r.root.event}`;
        break;
      case 'reset': text = `reset (${r.text ?? ''})`; break;
      case 'injection': text = `injection ${r.text ?? ''}`; break;
      case 'event': text = `${r.outcome ?? ''} ${r.event ?? ''}${r.text !== undefined ? ' (' + r.text + ')' : ''}`; break;
      case 'overflow': text = `${r.dropped ?? 0} records dropped`; break;
      case 'coordinator': text = `coordinator ${r.text ?? ''}`; break;
      default: text = r.kind;
    }
    if (r.to !== undefined && (r.kind === 'transition' || r.kind === 'component-transition')) item.classList.add(`to-${r.to}`);
    const body = element('span', 'body');
    body.append(element('span', 'where', where), ' ', element('span', 'what', text));
    item.append(body);
    list.prepend(item);
    while (list.childElementCount > kMaxTransitions) list.lastElementChild?.remove();
  }

  private onClick(e: MouseEvent): void {
    const target = e.target instanceof Element ? e.target.closest<HTMLElement>('[data-address]') : null;
    if (target === null || target.dataset.address === undefined) return;
    this.select(target.dataset.address);
  }

  private select(address: string): void {
    this.selected = address;
    this.markSelected();
    byId('cause-address').textContent = address;
    this.send({ op: 'explain', address });
  }

  private markSelected(): void {
    for (const el of document.querySelectorAll('.state.selected')) el.classList.remove('selected');
    for (const el of this.nodes.get(this.selected) ?? []) el.classList.add('selected');
  }

  private showCause(address: string, state: StateName, conditions: Condition[]): void {
    const box = byId('cause');
    box.replaceChildren();
    if (conditions.length === 0) {
      box.append(element('p', 'hint', `${address} is ${state}: no active condition.`));
      return;
    }
    box.append(element('p', 'hint', `${address} is ${state}: ${conditions.length} active condition${conditions.length === 1 ? '' : 's'}.`));
    for (const c of conditions) {
      const item = element('div', `condition level-${c.level}`);
      const flags = [c.outstanding ? 'outstanding' : '', c.mirror ? 'mirrored' : ''].filter((f) => f !== '').join(', ');
      item.append(element('div', 'head', `${c.machine}: ${c.event} (${c.level}, severity ${c.severity}${flags !== '' ? ', ' + flags : ''})`));
      let root = `root cause: ${c.root_event} at ${c.root_origin}, t=${seconds(c.root_t)}`;
      if (c.filter !== undefined) root += `; filter ${c.filter}`;
      if (c.signal !== undefined) root += `, ${c.signal} = ${c.value ?? ''} at t=${seconds(c.sample_t)}`;
      if (c.injected === true) root += ' (injected)';
      if (c.hazard !== undefined) root += `; hazard ${c.hazard}`;
      item.append(element('div', 'root', root));
      item.append(element('div', 'path', c.path.join(' → ')));
      // A live coordinator's explain does not carry the counts (count 0): no line then.
      if (c.count > 0) item.append(element('div', 'meta hint', `since t=${seconds(c.first)}, seen ${c.count}×, last t=${seconds(c.last)}`));
      box.append(item);
    }
  }
}

new Viewer().start();
