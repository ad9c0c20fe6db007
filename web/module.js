// The WebAssembly module (wasm/lib.rs) as the page and its worker load and
// call it: an instance, bytes put into its memory, its text read out.

const decoder = new TextDecoder();

// An instance of screensaver.wasm, beside this file.
export async function instantiate() {
  const url = new URL("screensaver.wasm", import.meta.url);
  try {
    return (await WebAssembly.instantiateStreaming(fetch(url), {})).instance.exports;
  } catch {
    // A server that does not say application/wasm.
    const bytes = await (await fetch(url)).arrayBuffer();
    return (await WebAssembly.instantiate(bytes, {})).instance.exports;
  }
}

// Copies `bytes` into a buffer of the module's (ss_alloc); gives where.
export function put(ss, bytes) {
  const at = ss.ss_alloc(bytes.length);
  new Uint8Array(ss.memory.buffer, at, bytes.length).set(bytes);
  return at;
}

// The module's text (ss_text_ptr, ss_text_len).
export function text(ss) {
  return decoder.decode(new Uint8Array(ss.memory.buffer, ss.ss_text_ptr(), ss.ss_text_len()));
}
