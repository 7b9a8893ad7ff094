// The page imports the graph layout library @dagrejs/dagre (web/package.json) as ./dagre.js, the
// package's ES module bundle that the viewer serves next to viewer.js; its types are the package's.
export * from '../node_modules/@dagrejs/dagre/dist/types/index';
