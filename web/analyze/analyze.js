// SAFECASS safety analysis report: draws the GSN goal structure (the page's JSON) as an SVG
// diagram laid out by dagre, the layout the live viewer's graph uses, whose module is inlined in
// the page as text. Without it the page keeps its indented tree. When done, body.dataset.gsn is
// "drawn" (or "tree"), for tests and for printing.
(function () {
  'use strict';
  const NS = 'http://www.w3.org/2000/svg';
  const data = JSON.parse(document.getElementById('gsn-data').textContent || '{"nodes":[]}');
  const source = document.getElementById('dagre-source').textContent || '';
  const figure = document.getElementById('gsn-figure');

  function lines(text, width) {
    const out = [];
    let line = '';
    for (const word of text.split(/\s+/)) {
      if (line !== '' && (line + ' ' + word).length > width) {
        out.push(line);
        line = word;
      } else {
        line = line === '' ? word : line + ' ' + word;
      }
    }
    if (line !== '') out.push(line);
    return out;
  }

  function el(name, attrs, parent) {
    const e = document.createElementNS(NS, name);
    for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
    if (parent) parent.appendChild(e);
    return e;
  }

  function shape(node, box, g) {
    const { width: w, height: h } = box;
    if (node.type === 'strategy') {
      el('polygon', { points: `${12},0 ${w},0 ${w - 12},${h} 0,${h}` }, g);
    } else if (node.type === 'solution') {
      el('ellipse', { cx: w / 2, cy: h / 2, rx: w / 2, ry: h / 2 }, g);
    } else if (node.type === 'context' || node.type === 'assumption') {
      el('rect', { width: w, height: h, rx: h / 2, ry: h / 2 }, g);
    } else {
      el('rect', { width: w, height: h }, g);
    }
    if (node.undeveloped) {
      el('polygon', { class: 'diamond', points: `${w / 2},${h} ${w / 2 + 8},${h + 8} ${w / 2},${h + 16} ${w / 2 - 8},${h + 8}` }, g);
    }
  }

  function draw(dagre) {
    const graph = new dagre.graphlib.Graph();
    graph.setGraph({ rankdir: 'TB', nodesep: 18, ranksep: 36, marginx: 8, marginy: 8 });
    graph.setDefaultEdgeLabel(() => ({}));
    const texts = new Map();
    for (const n of data.nodes) {
      const t = lines(n.text, n.type === 'solution' ? 22 : 30);
      texts.set(n.id, t);
      const width = n.type === 'solution' ? 170 : 200;
      graph.setNode(n.id, { width, height: 22 + 12 * t.length + (n.type === 'solution' ? 16 : 0) });
    }
    for (const n of data.nodes) {
      for (const c of n.supported_by) graph.setEdge(n.id, c, { kind: 'supported' });
      for (const c of n.in_context_of) graph.setEdge(n.id, c, { kind: 'context' });
    }
    dagre.layout(graph);
    const size = graph.graph();
    const svg = el('svg', { viewBox: `0 0 ${size.width} ${size.height + 20}`, role: 'img', 'aria-label': 'GSN goal structure' });
    for (const e of graph.edges()) {
      const points = graph.edge(e).points.map((p) => `${p.x},${p.y}`).join(' ');
      el('polyline', { class: 'edge ' + graph.edge(e).kind, points }, svg);
    }
    for (const n of data.nodes) {
      const box = graph.node(n.id);
      const g = el('g', { class: 'node ' + n.type + (n.undeveloped ? ' undeveloped' : ''), 'data-id': n.id,
        transform: `translate(${box.x - box.width / 2},${box.y - box.height / 2})` }, svg);
      shape(n, box, g);
      const top = n.type === 'solution' ? 14 : 6;
      el('text', { class: 'id', x: 8, y: top + 10 }, g).textContent = n.id + (n.undeveloped ? ' (undeveloped)' : '');
      texts.get(n.id).forEach((line, k) => { el('text', { x: 8, y: top + 24 + 12 * k }, g).textContent = line; });
    }
    figure.replaceChildren(svg);
    document.body.dataset.gsn = 'drawn';
  }

  if (source.trim() === '' || data.nodes.length === 0) {
    document.body.dataset.gsn = 'tree';
    return;
  }
  const url = URL.createObjectURL(new Blob([source], { type: 'text/javascript' }));
  import(url).then((m) => draw(m.default || m)).catch((e) => {
    document.body.dataset.gsn = 'tree';
    console.error('the GSN diagram could not be drawn: ' + e.message);
  });
})();
