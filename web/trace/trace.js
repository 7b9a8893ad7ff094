// SAFECASS hazard trace report: draws each hazard's timeline excerpt with the timeline page's
// renderer (SafecassTimeline.Chart, web/timeline/timeline.js), and draws them again at the
// printed width when the page is printed. Everything else on the page is static HTML.
(function () {
  'use strict';
  var charts = [];
  Array.prototype.forEach.call(document.querySelectorAll('figure.excerpt'), function (figure) {
    var model = JSON.parse(figure.querySelector('script.excerpt-model').textContent);
    var from = Number(figure.getAttribute('data-from'));
    var to = Number(figure.getAttribute('data-to'));
    var chart = SafecassTimeline.Chart({
      model: model,
      axis: figure.querySelector('svg.timeline-axis'),
      lanes: figure.querySelector('svg.timeline-lanes'),
      box: figure.querySelector('.excerpt-box'),
      view: to > from ? [from, to] : undefined
    });
    chart.render();
    charts.push(chart);
  });
  function redraw() { charts.forEach(function (c) { c.render(); }); }
  window.addEventListener('resize', redraw);
  window.addEventListener('beforeprint', redraw);
  if (window.matchMedia) {
    var print = window.matchMedia('print');
    if (print.addEventListener) print.addEventListener('change', redraw);
  }
  document.body.setAttribute('data-drawn', String(charts.length));
})();
