// Prepended to the Node-run programs (CMakeLists.txt, mcplay_node_program: the CLI, the bench),
// so that `node build-wasm/mcplay.js` behaves as the native program does:
// - the .wasm beside the script is read from disk: Emscripten's glue would otherwise try
//   fetch() first, which Node 18+ has and which cannot load a file path (the run then failed
//   unless node was given --no-experimental-fetch);
// - the process's environment reaches getenv ($MCPLAY_SCENES, $MCPLAY_CACHE, $HOME): the glue
//   otherwise gives the program a fixed environment of its own (USER=web_user, HOME=/home/...).
Module['wasmBinary'] = require('fs').readFileSync(__filename.replace(/\.js$/, '.wasm'));
Module['preRun'] = (Module['preRun'] || []).concat([function () {
  Object.assign(ENV, process.env);
}]);
