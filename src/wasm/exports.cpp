// The mcplay_web WebAssembly module (web/core.js is its only caller) has no code of its own:
// the C API lives in the mcplay_api library, and the functions it exports are listed in
// src/wasm/exported_functions.txt, which CMake passes to the linker as -sEXPORTED_FUNCTIONS
// (that keeps them, and pulls them out of the static library). This file exists only because
// an executable target needs a source.
