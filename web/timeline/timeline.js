// SAFECASS timeline: draws the model embedded in the page (element #timeline-model, built by
// `safecass timeline`) as swimlanes, and shows the raw history records (#timeline-history) on
// demand. Plain browser JavaScript, no libraries, no network.
//
// Two parts: the renderer (SafecassTimeline.Chart: one model drawn into an axis and a lanes SVG),
// which the trace report (web/trace) reuses for its excerpts, and the timeline page's wiring.
var SafecassTimeline = (function () {
  'use strict';

  var SVG = 'http://www.w3.org/2000/svg';
  var LABEL_W = 240;   // label column, px
  var RIGHT_PAD = 16;  // px right of the plot
  var GROUP_H = 24;    // component heading row
  var LANE_H = 30;     // one swimlane
  var BAR_PAD = 5;     // gap above and below a bar
  var AXIS_H = 30;
  var MIN_SPAN = 1e-6; // s: deepest zoom
  var STATE_TEXT = { Normal: 'Normal', Warning: 'Warning', Error: 'Error' };

  var charts = 0;      // ids of a chart's clip path and patterns are unique in the document

  // One chart: the swimlanes of `opts.model` drawn into `opts.axis` and `opts.lanes` (SVG
  // elements), as wide as `opts.box`. `opts.range` (optional) shows the visible span; `opts.view`
  // (optional, [from, to] in seconds) is the first view instead of the whole history.
  function Chart(opts) {
    var model = opts.model;
    var axisSvg = opts.axis;
    var lanesSvg = opts.lanes;
    var box = opts.box;
    var uid = charts++ === 0 ? '' : '-' + charts;

    // The whole history with a little air on both sides; the view never leaves it.
    var t0 = model.start;
    var t1 = model.end > model.start ? model.end : model.start + 1;
    var air = (t1 - t0) * 0.02;
    var home = [t0 - air, t1 + air];
    var view = opts.view ? opts.view.slice() : home.slice();
    var items = [];      // what a click on element data-item=i refers to
    var selected = null; // the item whose details are open
    var pending = false;

    function el(name, attrs, parent) {
      var e = document.createElementNS(SVG, name);
      for (var k in attrs) {
        if (Object.prototype.hasOwnProperty.call(attrs, k)) e.setAttribute(k, attrs[k]);
      }
      if (parent) parent.appendChild(e);
      return e;
    }

    function title(parent, text) {
      var t = el('title', {}, parent);
      t.textContent = text;
    }

    function plotWidth() {
      var w = box.clientWidth - 24;  // main's horizontal padding
      return Math.max(100, w - LABEL_W - RIGHT_PAD);
    }

    function x(t, w) { return LABEL_W + (t - view[0]) / (view[1] - view[0]) * w; }

    function niceStep(raw) {
      var p = Math.pow(10, Math.floor(Math.log10(raw)));
      var n = raw / p;
      return (n < 1.5 ? 1 : n < 3.5 ? 2 : n < 7.5 ? 5 : 10) * p;
    }

    function ticks(w) {
      var span = view[1] - view[0];
      var step = niceStep(span / Math.max(2, Math.floor(w / 90)));
      var digits = Math.min(9, Math.max(0, Math.ceil(-Math.log10(step) - 1e-9)));
      var out = [];
      // Counted in whole steps (never t += step), so that rounding cannot stall the loop.
      for (var k = Math.ceil(view[0] / step); k * step <= view[1] + step * 1e-9 && out.length < 200; k++) {
        var t = k * step;
        out.push({ t: t, text: (k === 0 ? 0 : t).toFixed(digits) });
      }
      return out;
    }

    function seconds(t) {
      var digits = Math.min(9, Math.max(0, Math.ceil(-Math.log10((view[1] - view[0]) / 1000))));
      return t.toFixed(digits) + ' s';
    }

    function clampView() {
      var span = Math.min(view[1] - view[0], home[1] - home[0]);
      span = Math.max(span, MIN_SPAN);
      var a = Math.min(Math.max(view[0], home[0]), home[1] - span);
      view = [a, a + span];
    }

    function zoom(factor, at) {
      if (at === undefined) at = (view[0] + view[1]) / 2;
      view = [at - (at - view[0]) * factor, at + (view[1] - at) * factor];
      clampView();
      schedule();
    }

    function pan(fraction) {
      var d = (view[1] - view[0]) * fraction;
      view = [view[0] + d, view[1] + d];
      clampView();
      schedule();
    }

    function schedule() {
      if (pending) return;
      pending = true;
      window.requestAnimationFrame(function () { pending = false; render(); });
    }

    function renderAxis(w, marks) {
      while (axisSvg.firstChild) axisSvg.removeChild(axisSvg.firstChild);
      axisSvg.setAttribute('height', AXIS_H);
      el('line', { 'class': 'tick', x1: LABEL_W, x2: LABEL_W + w, y1: AXIS_H - 1, y2: AXIS_H - 1 }, axisSvg);
      var unit = el('text', { 'class': 'unit', x: LABEL_W - 8, y: AXIS_H - 10, 'text-anchor': 'end' }, axisSvg);
      unit.textContent = 'time (s)';
      marks.forEach(function (m) {
        var px = x(m.t, w);
        el('line', { 'class': 'tick', x1: px, x2: px, y1: AXIS_H - 7, y2: AXIS_H - 1 }, axisSvg);
        var label = el('text', { x: px, y: AXIS_H - 11, 'text-anchor': 'middle' }, axisSvg);
        label.textContent = m.text;
      });
    }

    function defs(svg, w, h) {
      var d = el('defs', {}, svg);
      var clip = el('clipPath', { id: 'plot-clip' + uid }, d);
      el('rect', { x: LABEL_W, y: 0, width: w, height: h }, clip);
      // Patterns tell the states apart without colour: Warning striped, Error cross-hatched.
      var pw = el('pattern', { id: 'hatch-Warning' + uid, width: 6, height: 6, patternUnits: 'userSpaceOnUse', patternTransform: 'rotate(45)' }, d);
      el('line', { x1: 0, y1: 0, x2: 0, y2: 6, stroke: 'rgba(0,0,0,0.22)', 'stroke-width': 1.5 }, pw);
      var pe = el('pattern', { id: 'hatch-Error' + uid, width: 6, height: 6, patternUnits: 'userSpaceOnUse', patternTransform: 'rotate(45)' }, d);
      el('path', { d: 'M0,0V6M0,0H6', stroke: 'rgba(255,255,255,0.28)', 'stroke-width': 1.5 }, pe);
      var po = el('pattern', { id: 'overflow-hatch' + uid, width: 8, height: 8, patternUnits: 'userSpaceOnUse', patternTransform: 'rotate(-45)' }, d);
      el('rect', { width: 8, height: 8, fill: 'rgba(242,169,0,0.12)' }, po);
      el('line', { x1: 0, y1: 0, x2: 0, y2: 8, stroke: 'rgba(242,169,0,0.55)', 'stroke-width': 2 }, po);
    }

    function addItem(node, item) {
      node.setAttribute('data-item', items.length);
      if (item === selected) node.classList.add('selected');
      items.push(item);
      var t = document.createElementNS(SVG, 'title');
      t.textContent = item.tip;
      node.insertBefore(t, node.firstChild);
    }

    function drawBar(g, lane, bar, y, w) {
      var right = LABEL_W + w;
      var xa = x(bar.from, w);
      var xb = bar.to === null ? Math.max(right, xa) : x(bar.to, w);
      if (xb < LABEL_W || xa > right) return;
      xa = Math.max(xa, LABEL_W - 2);
      xb = Math.min(xb, right + 2);
      var bw = Math.max(2, xb - xa);  // an instant in a state stays visible
      var h = LANE_H - 2 * BAR_PAD;
      var r = el('rect', { 'class': 'bar state-' + bar.state, x: xa, y: y + BAR_PAD, width: bw, height: h }, g);
      addItem(r, bar);
      if (bar.state !== 'Normal') {
        el('rect', { 'class': 'bar-hatch', x: xa, y: y + BAR_PAD, width: bw, height: h, fill: 'url(#hatch-' + bar.state + uid + ')' }, g);
      }
      var visA = Math.max(xa, LABEL_W), visB = Math.min(xa + bw, right);
      var room = visB - visA;
      var text = STATE_TEXT[bar.state] || bar.state;
      if (room < text.length * 7 + 8) text = room >= 14 ? text.charAt(0) : '';
      if (text) {
        var t = el('text', { 'class': 'bar-text state-' + bar.state, x: (visA + visB) / 2, y: y + LANE_H - BAR_PAD - 5, 'text-anchor': 'middle' }, g);
        t.textContent = text;
      }
    }

    function markerShape(g, kind, cx, cy) {
      var m = el('g', { 'class': 'marker', transform: 'translate(' + cx + ',' + cy + ')' }, g);
      el('rect', { x: -7, y: -7, width: 14, height: 14, fill: 'transparent' }, m);  // easier to hit
      if (kind === 'ignored') {
        el('path', { 'class': 'marker-ignored-halo', d: 'M-4,-4L4,4M4,-4L-4,4' }, m);
        el('path', { 'class': 'marker-ignored', d: 'M-4,-4L4,4M4,-4L-4,4' }, m);
      } else if (kind === 'masked') {
        el('path', { 'class': 'marker-masked', d: 'M0,-5L5,0L0,5L-5,0Z' }, m);
      } else if (kind === 'injection') {
        el('path', { 'class': 'marker-injection', d: 'M-6,-5L6,-5L0,6Z' }, m);
      } else if (kind === 'reset') {
        el('rect', { 'class': 'marker-reset', x: -4, y: -4, width: 8, height: 8 }, m);
      } else {
        el('circle', { 'class': 'marker-condition', r: 3.5 }, m);
      }
      return m;
    }

    function render() {
      var w = plotWidth();
      items = [];
      var marks = ticks(w);
      renderAxis(w, marks);
      if (opts.range) opts.range.textContent =
        'showing ' + seconds(view[0]) + ' to ' + seconds(view[1]) + ' of ' + seconds(model.start) + ' to ' + seconds(model.end);

      while (lanesSvg.firstChild) lanesSvg.removeChild(lanesSvg.firstChild);
      var rows = 0;
      model.groups.forEach(function (g) { rows += GROUP_H + g.lanes.length * LANE_H; });
      var h = rows + 8;
      lanesSvg.setAttribute('height', h);
      lanesSvg.style.display = model.groups.length === 0 ? 'none' : '';
      defs(lanesSvg, w, h);

      var grid = el('g', { 'clip-path': 'url(#plot-clip' + uid + ')' }, lanesSvg);
      marks.forEach(function (m) {
        var px = x(m.t, w);
        el('line', { 'class': 'grid', x1: px, x2: px, y1: 0, y2: h }, grid);
      });

      var plot = el('g', { 'clip-path': 'url(#plot-clip' + uid + ')' }, lanesSvg);
      var labels = el('g', {}, lanesSvg);
      var markers = el('g', { 'clip-path': 'url(#plot-clip' + uid + ')' }, lanesSvg);
      var y = 0;
      model.groups.forEach(function (g) {
        el('line', { 'class': 'group-rule', x1: 0, x2: LABEL_W + w, y1: y + 0.5, y2: y + 0.5 }, labels);
        var gl = el('text', { 'class': 'group-label', x: 4, y: y + GROUP_H - 7 }, labels);
        gl.textContent = g.component;
        y += GROUP_H;
        g.lanes.forEach(function (lane) {
          el('rect', { 'class': 'lane-bg', x: LABEL_W, y: y + 1, width: w, height: LANE_H - 2 }, plot);
          var isComponent = lane.kind === 'component';
          var label = el('text', { 'class': 'lane-label' + (isComponent ? ' component' : ''), x: 16, y: y + LANE_H / 2 + 4 }, labels);
          var name = isComponent ? lane.address + ' (extended state)' : lane.address;
          label.textContent = name.length > 34 ? name.slice(0, 33) + '\u2026' : name;
          title(label, name);
          lane.bars.forEach(function (bar) { drawBar(plot, lane, bar, y, w); });
          // Markers sit on the bar's top edge, clear of its text; markers that would hide one another
          // (same instant at this zoom) go to the bottom edge, then step to the right.
          var placed = [];
          lane.markers.forEach(function (mk) {
            var px = x(mk.t, w);
            if (px < LABEL_W - 8 || px > LABEL_W + w + 8) return;
            var k = placed.filter(function (q) { return Math.abs(q - px) < 9; }).length;
            placed.push(px);
            var my = k % 2 === 0 ? y + BAR_PAD + 1 : y + LANE_H - BAR_PAD - 1;
            addItem(markerShape(markers, mk.kind, px + Math.floor(k / 2) * 10, my), mk);
          });
          y += LANE_H;
        });
      });

      var bands = el('g', { 'clip-path': 'url(#plot-clip' + uid + ')' }, lanesSvg);
      model.overflows.forEach(function (o) {
        var xa = x(o.from, w);
        var xb = o.to === null ? LABEL_W + w : x(o.to, w);
        if (xb - xa < 6) { xa -= 3; xb = xa + 6; }  // a short gap stays visible
        var r = el('rect', { 'class': 'overflow-band', x: xa, y: 0, width: xb - xa, height: h }, bands);
        addItem(r, o);
        var t = el('text', { 'class': 'overflow-text', x: xa + 3, y: 12 }, bands);
        t.textContent = '\u26A0 ' + o.dropped + ' dropped';
      });
    }

    clampView();
    return {
      render: render,
      zoom: zoom,
      pan: pan,
      fit: function () { view = home.slice(); schedule(); },
      schedule: schedule,
      plotWidth: plotWidth,
      getView: function () { return view.slice(); },
      setView: function (v) { view = v.slice(); clampView(); schedule(); },
      item: function (i) { return items[i]; },
      select: function (item) { selected = item; schedule(); }
    };
  }

  return { Chart: Chart, LABEL_WIDTH: LABEL_W };
})();

// The timeline page: one chart of the whole history, with zoom and pan, the details of a clicked
// item, and the table of every record. Does nothing on a page without #timeline-model (a page that
// only uses the renderer above, such as the trace report).
(function () {
  'use strict';
  var modelNode = document.getElementById('timeline-model');
  if (!modelNode) return;
  var model = JSON.parse(modelNode.textContent);
  var history = JSON.parse(document.getElementById('timeline-history').textContent);
  var lanesSvg = document.getElementById('lanes');
  var chart = SafecassTimeline.Chart({
    model: model, axis: document.getElementById('axis'), lanes: lanesSvg,
    box: document.getElementById('lanes-box'), range: document.getElementById('range')
  });

  // Details of a clicked bar, marker or band: its explanation and the history line behind it.
  function showDetails(i) {
    var item = chart.item(i);
    if (!item) return;
    document.getElementById('details-tip').textContent = item.tip;
    var rec = item.line ? history[item.line - 1] : null;
    document.getElementById('details-record').textContent =
      rec ? 'history line ' + item.line + ':\n' + JSON.stringify(rec, null, 1) : '';
    document.getElementById('details').hidden = false;
    chart.select(item);
  }

  function hideDetails() {
    document.getElementById('details').hidden = true;
    chart.select(null);
  }

  function recordsTable() {
    var holder = document.getElementById('records-table');
    if (holder.firstChild) return;
    var table = document.createElement('table');
    var head = table.createTHead().insertRow();
    ['line', 't (s)', 'kind', 'outcome', 'where', 'event', 'state', 'root cause', 'text'].forEach(function (c) {
      var th = document.createElement('th');
      th.textContent = c;
      head.appendChild(th);
    });
    var body = table.createTBody();
    history.forEach(function (r, i) {
      var row = body.insertRow();
      var root = r.root ? r.root.origin + ':' + r.root.event : '';
      var state = r.from !== undefined ? r.from + ' \u2192 ' + r.to : '';
      var kind = r.kind === 'overflow' ? 'overflow (' + r.dropped + ' dropped)' : r.kind;
      [i + 1, r.t !== undefined ? r.t : '', kind, r.outcome || '', r.machine || r.component || '', r.event || '', state, root, r.text || '']
        .forEach(function (v, k) {
          var td = row.insertCell();
          td.textContent = String(v);
          if (k < 2) td.className = 'num';
        });
    });
    holder.appendChild(table);
  }

  // Pointer: drag pans, a click (no drag) opens the details of what is under it.
  var drag = null;
  lanesSvg.addEventListener('pointerdown', function (e) {
    if (e.button !== 0) return;
    drag = { x: e.clientX, view: chart.getView(), moved: false, target: e.target };
    lanesSvg.setPointerCapture(e.pointerId);
  });
  lanesSvg.addEventListener('pointermove', function (e) {
    if (!drag) return;
    var dx = e.clientX - drag.x;
    if (!drag.moved && Math.abs(dx) < 4) return;
    drag.moved = true;
    lanesSvg.classList.add('dragging');
    var d = -dx / chart.plotWidth() * (drag.view[1] - drag.view[0]);
    chart.setView([drag.view[0] + d, drag.view[1] + d]);
  });
  function endDrag() {
    if (!drag) return;
    if (!drag.moved) {
      var node = drag.target;
      while (node && node !== lanesSvg && !(node.getAttribute && node.getAttribute('data-item') !== null)) node = node.parentNode;
      if (node && node !== lanesSvg) showDetails(Number(node.getAttribute('data-item')));
    }
    drag = null;
    lanesSvg.classList.remove('dragging');
  }
  lanesSvg.addEventListener('pointerup', endDrag);
  lanesSvg.addEventListener('pointercancel', endDrag);

  // Wheel over the plot zooms around the pointer; a horizontal or shifted wheel pans.
  lanesSvg.addEventListener('wheel', function (e) {
    var rect = lanesSvg.getBoundingClientRect();
    var px = e.clientX - rect.left;
    if (px < SafecassTimeline.LABEL_WIDTH) return;  // over the labels: let the page scroll
    e.preventDefault();
    var unit = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? 400 : 1;
    var w = chart.plotWidth();
    var view = chart.getView();
    if (e.shiftKey || Math.abs(e.deltaX) > Math.abs(e.deltaY)) {
      chart.pan(((e.shiftKey ? e.deltaY : 0) + e.deltaX) * unit / w);
      return;
    }
    var at = view[0] + (px - SafecassTimeline.LABEL_WIDTH) / w * (view[1] - view[0]);
    chart.zoom(Math.exp(e.deltaY * unit * 0.0015), at);
  }, { passive: false });

  document.getElementById('zoom-in').addEventListener('click', function () { chart.zoom(0.5); });
  document.getElementById('zoom-out').addEventListener('click', function () { chart.zoom(2); });
  document.getElementById('pan-left').addEventListener('click', function () { chart.pan(-0.25); });
  document.getElementById('pan-right').addEventListener('click', function () { chart.pan(0.25); });
  document.getElementById('zoom-fit').addEventListener('click', function () { chart.fit(); });
  document.getElementById('details-close').addEventListener('click', hideDetails);
  document.getElementById('records').addEventListener('toggle', recordsTable);
  document.addEventListener('keydown', function (e) {
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    var handled = true;
    if (e.key === '+' || e.key === '=') chart.zoom(0.5);
    else if (e.key === '-' || e.key === '_') chart.zoom(2);
    else if (e.key === 'ArrowLeft') chart.pan(-0.1);
    else if (e.key === 'ArrowRight') chart.pan(0.1);
    else if (e.key === '0') chart.fit();
    else if (e.key === 'Escape') hideDetails();
    else handled = false;
    if (handled) e.preventDefault();
  });
  window.addEventListener('resize', chart.schedule);

  var empty = document.getElementById('empty');
  empty.hidden = model.transitions > 0;
  if (model.records === 0) empty.textContent = 'No transitions: the history is empty.';
  chart.render();
})();
