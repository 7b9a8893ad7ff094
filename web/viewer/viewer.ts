// The SAFECASS live viewer page: draws coordinators → components → machines from the server's
// "hello", and a graph of the components and their connections (laid out by @dagrejs/dagre);
// keeps both current from its "update" pushes, shows the cause of a clicked state ("explain")
// with its hop path highlighted in the graph and, when the viewer was started with
// --allow-write, sends generate / inject / reset requests carrying the token. A replay
// (`safecass viewer --replay`) gets a time slider: play, pause, speed, seek, next transition.
// The protocol is documented in tools/viewer/include/safecass/viewer/protocol.hpp.

import { graphlib, layout } from './dagre.js';

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

interface ConnectionView {
  required: string;  // "CONTROL.ForceData"
  provided: string;  // "JR3.ForceData"
}

/** Scenario seconds, or a live system's host clock shown as wall-clock time. */
type ClockView = { base: 'simulated' } | { base: 'host'; wall_offset_ms: number };

interface ReplayView {
  start: number;
  end: number;
  period: number;
  playing: boolean;
  speed: number;
  busy: '' | 'seek' | 'next';
}

interface SystemView {
  system: string;
  description: string;
  t: number;
  running: boolean;
  state: StateName;
  coordinators: CoordinatorView[];
  connections?: ConnectionView[];
  clock?: ClockView;
  replay?: ReplayView;
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

/** `analyze now` (coverage_now_json): each hazard and why it cannot be detected now. */
interface CoverageGap { onset: string; reason: string }
interface HazardCoverage { hazard: string; covered: boolean; onsets: string[]; gaps: CoverageGap[] }
interface Coverage { t: number; uncovered: number; hazards: HazardCoverage[] }

interface Hello { type: 'hello'; write: boolean; max_message: number; view: SystemView; coverage: Coverage; recent: HistoryRecord[] }
interface Update { type: 'update'; t: number; running: boolean; states: Record<string, [StateName, string]>; records: HistoryRecord[]; coverage?: Coverage; replay?: ReplayView }
interface TimeMessage { type: 'time'; t: number; running: boolean; replay?: ReplayView }
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

function pad(n: number, width = 2): string {
  return String(Math.trunc(n)).padStart(width, '0');
}

/** ISO 8601 in the local zone with milliseconds, as the read model writes a live system's times:
 *  "2026-03-01T14:02:11.532+01:00". */
export function iso8601Local(unixMs: number): string {
  const d = new Date(Math.floor(unixMs));
  const offset = -d.getTimezoneOffset();  // minutes east of UTC
  const off = Math.abs(offset);
  return `${pad(d.getFullYear(), 4)}-${pad(d.getMonth() + 1)}-${pad(d.getDate())}T${pad(d.getHours())}:` +
    `${pad(d.getMinutes())}:${pad(d.getSeconds())}.${pad(d.getMilliseconds(), 3)}${offset < 0 ? '-' : '+'}` +
    `${pad(off / 60)}:${pad(off % 60)}`;
}

/** The component of an address: "CONTROL.s_R.ForceData" → "CONTROL". */
function componentOf(address: string): string {
  const dot = address.indexOf('.');
  return dot < 0 ? address : address.slice(0, dot);
}

const kSvg = 'http://www.w3.org/2000/svg';

function svg(tag: string, className: string, attributes: Record<string, string | number> = {}): SVGElement {
  const el = document.createElementNS(kSvg, tag) as SVGElement;
  if (className !== '') el.setAttribute('class', className);
  for (const [k, v] of Object.entries(attributes)) el.setAttribute(k, String(v));
  return el;
}

/** The graph edges of a hop path: consecutive hops "P.s_S.p" → "C.s_R.r" cross the connection
 *  from P's provided interface p to C's required interface r. */
function pathEdges(path: string[]): { provided: string; required: string }[] {
  const edges: { provided: string; required: string }[] = [];
  for (let i = 0; i + 1 < path.length; i += 1) {
    const from = /^([^.]+)\.s_S\.(.+)$/.exec(path[i]);
    const to = /^([^.]+)\.s_R\.(.+)$/.exec(path[i + 1]);
    if (from !== null && to !== null) edges.push({ provided: `${from[1]}.${from[2]}`, required: `${to[1]}.${to[2]}` });
  }
  return edges;
}

type Node = HTMLElement | SVGElement;

class Viewer {
  private socket: WebSocket | null = null;
  private nodes = new Map<string, Node[]>();
  private clock: ClockView = { base: 'simulated' };
  private replay: ReplayView | null = null;
  private scrubbing = false;
  private conditions: Condition[] = [];
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
    byId('replay-play').addEventListener('click', () => {
      this.send({ op: 'replay', action: this.replay !== null && this.replay.playing ? 'pause' : 'play' });
    });
    byId('replay-next').addEventListener('click', () => this.send({ op: 'replay', action: 'next' }));
    byId<HTMLSelectElement>('replay-speed').addEventListener('change', (e) => {
      this.send({ op: 'replay', action: 'speed', speed: Number((e.target as HTMLSelectElement).value) });
    });
    const slider = byId<HTMLInputElement>('replay-slider');
    slider.addEventListener('input', () => {
      this.scrubbing = true;
      byId('replay-time').textContent = `${seconds(Number(slider.value))} s`;
    });
    slider.addEventListener('change', () => {
      this.scrubbing = false;
      this.send({ op: 'replay', action: 'seek', t: Number(slider.value) });
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
      case 'time':
        this.setClock(m.t, m.running);
        if (m.replay !== undefined) this.setReplay(m.replay, m.t);
        return;
      case 'reply': return this.onReply(m);
      case 'error': return this.onError(m);
    }
  }

  private onHello(m: Hello): void {
    this.clock = m.view.clock ?? { base: 'simulated' };
    this.replay = null;
    this.render(m.view);
    byId('replay-bar').hidden = m.view.replay === undefined;
    // Connected to a replay: what is shown is the recording, not a system running now.
    if (m.view.replay !== undefined) byId('connection').textContent = 'replay';
    if (m.view.replay !== undefined) this.setReplay(m.view.replay, m.view.t);
    byId('write-panel').hidden = !m.write;
    this.showCoverage(m.coverage);
    const list = byId('transitions');
    list.replaceChildren();
    for (const r of m.recent) this.addTransition(r);
    if (this.selected !== '') this.select(this.selected);
  }

  private onUpdate(m: Update): void {
    this.setClock(m.t, m.running);
    if (m.replay !== undefined) this.setReplay(m.replay, m.t);
    let selectedChanged = false;
    // A state the page has not drawn (a live coordinator now answers with another shape): redraw.
    if (Object.keys(m.states).some((address) => !this.nodes.has(address))) this.send({ op: 'view' });
    for (const [address, [state, outstanding]] of Object.entries(m.states)) {
      this.setState(address, state, outstanding);
      if (address === this.selected) selectedChanged = true;
    }
    for (const r of m.records) this.addTransition(r);
    if (m.coverage !== undefined) this.showCoverage(m.coverage);
    if (selectedChanged) this.select(this.selected);
  }

  /** Each hazard, an uncovered one marked with what leaves it undetected now. */
  private showCoverage(c: Coverage): void {
    const list = byId('hazards');
    list.replaceChildren();
    if (c.hazards.length === 0) list.append(element('li', 'hint', 'no onset names a hazard'));
    for (const h of c.hazards) {
      const item = element('li', h.covered ? 'hazard covered' : 'hazard uncovered');
      item.dataset.hazard = h.hazard;
      item.append(element('span', 'hazard-name', h.hazard), element('span', 'hazard-verdict', h.covered ? 'covered' : 'UNCOVERED'));
      item.title = `onsets: ${h.onsets.join(', ')}`;
      for (const g of h.gaps) item.append(element('div', 'hazard-gap', `${g.onset}: ${g.reason}`));
      list.append(item);
    }
    byId('hazards-summary').textContent = c.hazards.length === 0 ? '' : `${c.uncovered} of ${c.hazards.length} uncovered now`;
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
    } else if (op === 'replay') {
      this.showReplayResult(true, m.text ?? 'done');
    }
  }

  private onError(m: ErrorReply): void {
    const op = m.id !== undefined ? this.pending.get(m.id) ?? m.op ?? '' : m.op ?? '';
    if (m.id !== undefined) this.pending.delete(m.id);
    if (op === 'explain') {
      byId('cause').replaceChildren(element('p', 'result error', m.error));
    } else if (op === 'replay') {
      this.showReplayResult(false, m.error);
    } else {
      this.showResult(false, m.error);
    }
  }

  private showResult(ok: boolean, text: string): void {
    const result = byId('write-result');
    result.textContent = text;
    result.className = ok ? 'result ok' : 'result error';
  }

  private showReplayResult(ok: boolean, text: string): void {
    const result = byId('replay-result');
    result.textContent = text;
    result.className = ok ? 'result ok' : 'result error';
  }

  /** A time of the system: scenario seconds, or (a live system) wall-clock time. */
  private time(t: number | undefined): string {
    if (t === undefined) return '–';
    return this.clock.base === 'host' ? iso8601Local(t * 1000 + this.clock.wall_offset_ms) : seconds(t);
  }

  private setClock(t: number, running: boolean): void {
    const clock = byId('clock');
    clock.dataset.t = String(t);
    if (this.clock.base === 'host') {
      clock.textContent = this.time(t);
    } else if (this.replay !== null) {
      clock.textContent = `t = ${seconds(t)} s`;
    } else {
      clock.textContent = `t = ${seconds(t)} s${running ? '' : ' (no scenario steps left: the system stays up)'}`;
    }
  }

  private setReplay(r: ReplayView, t: number): void {
    this.replay = r;
    const slider = byId<HTMLInputElement>('replay-slider');
    slider.min = String(r.start);
    slider.max = String(r.end);
    slider.step = String(r.period > 0 ? r.period : 0.001);
    if (!this.scrubbing) {
      slider.value = String(t);
      byId('replay-time').textContent = `${seconds(t)} s`;
    }
    byId('replay-end').textContent = `of ${seconds(r.start)}–${seconds(r.end)} s`;
    byId('replay-play').textContent = r.playing ? 'Pause' : 'Play';
    const speed = byId<HTMLSelectElement>('replay-speed');
    if (document.activeElement !== speed) speed.value = String(r.speed);
    const bar = byId('replay-bar');
    bar.dataset.busy = r.busy;
    bar.dataset.playing = String(r.playing);
    bar.dataset.t = String(t);
  }

  private register(address: string, el: Node): void {
    const list = this.nodes.get(address);
    if (list === undefined) this.nodes.set(address, [el]); else list.push(el);
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
    this.register(address, el);
    return el;
  }

  /** The components as a graph, laid out left to right along their connections (provider →
   *  client, the way errors propagate), each node coloured by the component's state. */
  private renderGraph(v: SystemView): void {
    const root = byId('graph');
    const g = new graphlib.Graph({ multigraph: true });
    g.setGraph({ rankdir: 'LR', nodesep: 18, ranksep: 70, marginx: 6, marginy: 6 });
    g.setDefaultEdgeLabel(() => ({}));
    const components = new Map<string, ComponentView>();
    for (const co of v.coordinators) for (const c of co.components) components.set(c.name, c);
    // Wide enough for the name and for an outstanding event such as EVT_SERVICE_FAILURE.
    for (const c of components.values()) g.setNode(c.name, { width: Math.max(136, c.name.length * 9 + 28), height: 42 });
    const connections = (v.connections ?? []).filter((c) =>
      components.has(componentOf(c.provided)) && components.has(componentOf(c.required)));
    for (const c of connections) g.setEdge(componentOf(c.provided), componentOf(c.required), { provided: c.provided, required: c.required }, c.required);
    layout(g);
    const size = g.graph();
    const width = Math.ceil(size.width ?? 0);
    const height = Math.ceil(size.height ?? 0);
    const drawing = svg('svg', 'graph-drawing', { width, height, viewBox: `0 0 ${width} ${height}`, role: 'img' });
    const caption = svg('title', '');
    caption.textContent = `components of ${v.system} and their connections`;
    drawing.append(caption);
    const defs = svg('defs', '');
    const marker = svg('marker', '', { id: 'arrow', viewBox: '0 0 10 10', refX: 9, refY: 5, markerWidth: 9, markerHeight: 9, markerUnits: 'userSpaceOnUse', orient: 'auto-start-reverse' });
    marker.append(svg('path', 'arrow-head', { d: 'M 0 0 L 10 5 L 0 10 z' }));
    defs.append(marker);
    drawing.append(defs);
    for (const e of g.edges()) {
      const label = g.edge(e) as { points?: { x: number; y: number }[]; provided?: string; required?: string };
      const points = label.points ?? [];
      if (points.length === 0) continue;
      const d = points.map((p, i) => `${i === 0 ? 'M' : 'L'} ${p.x.toFixed(1)} ${p.y.toFixed(1)}`).join(' ');
      const edge = svg('path', 'gedge', { d, 'marker-end': 'url(#arrow)' });
      edge.dataset.provided = label.provided ?? '';
      edge.dataset.required = label.required ?? '';
      const title = svg('title', '');
      title.textContent = `${label.provided ?? ''} → ${label.required ?? ''}`;
      edge.append(title);
      drawing.append(edge);
    }
    for (const name of g.nodes()) {
      const n = g.node(name) as { x: number; y: number; width: number; height: number };
      const c = components.get(name);
      if (c === undefined) continue;
      const node = svg('g', `gnode state-${c.state}`, { transform: `translate(${(n.x - n.width / 2).toFixed(1)} ${(n.y - n.height / 2).toFixed(1)})`, tabindex: 0, role: 'button' });
      node.dataset.address = c.name;
      node.dataset.component = c.name;
      node.dataset.state = c.state;
      node.append(svg('rect', 'gbox', { width: n.width, height: n.height, rx: 5, ry: 5 }));
      const label = svg('text', 'glabel', { x: n.width / 2, y: 17, 'text-anchor': 'middle' });
      label.textContent = c.name;
      const event = svg('text', 'event', { x: n.width / 2, y: 33, 'text-anchor': 'middle' });
      event.textContent = c.outstanding;
      node.append(label, event);
      this.register(c.name, node);
      drawing.append(node);
    }
    root.replaceChildren(drawing);
    byId('graph-panel').hidden = components.size === 0;
  }

  /** Highlights the hop path of `c` (from its root to the selected address) in the graph. */
  private highlight(c: Condition | null): void {
    for (const el of document.querySelectorAll('#graph .on-path')) el.classList.remove('on-path');
    const info = byId('graph-path');
    info.replaceChildren();
    delete info.dataset.hops;
    if (c === null) return;
    const components = new Set(c.path.map(componentOf));
    for (const el of document.querySelectorAll<SVGElement>('#graph .gnode')) {
      if (components.has(el.dataset.component ?? '')) el.classList.add('on-path');
    }
    for (const e of pathEdges(c.path)) {
      for (const el of document.querySelectorAll<SVGElement>('#graph .gedge')) {
        if (el.dataset.provided === e.provided && el.dataset.required === e.required) el.classList.add('on-path');
      }
    }
    info.dataset.hops = JSON.stringify(c.path);
    info.append(element('span', 'hint', `path of ${c.machine} (${c.root_origin}:${c.root_event}): `),
      element('span', 'address', c.path.join(' → ')));
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
    this.renderGraph(v);
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
      if (el instanceof HTMLElement) el.title = `${address}: ${state}${outstanding !== '' ? ' (' + outstanding + ')' : ''}`;
      if (address === 'SYSTEM') el.textContent = `SYSTEM ${state}`;
      if (!before && el instanceof HTMLElement) {
        el.classList.remove('flash');
        void el.offsetWidth;  // restart the animation
        el.classList.add('flash');
      }
    }
  }

  private addTransition(r: HistoryRecord): void {
    const list = byId('transitions');
    const item = element('li', `kind-${r.kind}`);
    item.append(element('span', 't', this.time(r.t)));
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
    const condition = e.target instanceof Element ? e.target.closest<HTMLElement>('[data-condition]') : null;
    if (condition !== null) {
      this.highlight(this.conditions[Number(condition.dataset.condition)] ?? null);
      return;
    }
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
    for (const el of document.querySelectorAll('.state.selected, .gnode.selected')) el.classList.remove('selected');
    for (const el of this.nodes.get(this.selected) ?? []) el.classList.add('selected');
  }

  private showCause(address: string, state: StateName, conditions: Condition[]): void {
    const box = byId('cause');
    box.replaceChildren();
    this.conditions = conditions;
    // The path shown in the graph: the outstanding condition's (what the state is because of).
    this.highlight(conditions.find((c) => c.outstanding) ?? conditions[0] ?? null);
    if (conditions.length === 0) {
      box.append(element('p', 'hint', `${address} is ${state}: no active condition.`));
      return;
    }
    box.append(element('p', 'hint', `${address} is ${state}: ${conditions.length} active condition${conditions.length === 1 ? '' : 's'}.`));
    for (const c of conditions) {
      const item = element('div', `condition level-${c.level}`);
      item.dataset.condition = String(this.conditions.indexOf(c));
      item.title = 'show its path in the graph';
      const flags = [c.outstanding ? 'outstanding' : '', c.mirror ? 'mirrored' : ''].filter((f) => f !== '').join(', ');
      item.append(element('div', 'head', `${c.machine}: ${c.event} (${c.level}, severity ${c.severity}${flags !== '' ? ', ' + flags : ''})`));
      const at = this.clock.base === 'host' ? ' at ' : ', t=';
      let root = `root cause: ${c.root_event} at ${c.root_origin}${at}${this.time(c.root_t)}`;
      if (c.filter !== undefined) root += `; filter ${c.filter}`;
      if (c.signal !== undefined) root += `, ${c.signal} = ${c.value ?? ''}${this.clock.base === 'host' ? ' at ' : ' at t='}${this.time(c.sample_t)}`;
      if (c.injected === true) root += ' (injected)';
      if (c.hazard !== undefined) root += `; hazard ${c.hazard}`;
      item.append(element('div', 'root', root));
      item.append(element('div', 'path', c.path.join(' → ')));
      // A live coordinator's explain does not carry the counts (count 0): no line then.
      const t = this.clock.base === 'host' ? '' : 't=';
      if (c.count > 0) item.append(element('div', 'meta hint', `since ${t}${this.time(c.first)}, seen ${c.count}×, last ${t}${this.time(c.last)}`));
      box.append(item);
    }
  }
}

new Viewer().start();
