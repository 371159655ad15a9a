// kernel.wasm in the page (web/wasm/kernel.cpp: the library's client replay of a frame,
// src/remora/multires/frame_replay.h, and the drawn mesh's normals): compiled once, one instance
// per region whose memory holds that region's data and goes with it. The memory is shared, so
// that a worker (web/kernel_worker.js) evaluates one half of each step of a frame on the second
// core while the page evaluates the other; sharing memory needs a cross-origin isolated page,
// which `remora serve` gives (its COOP and COEP headers). Without kernel.wasm, or without
// isolation, the frames are evaluated in JavaScript (web/kernel.js, web/normals.js).

let wasmModule = null, heapBase = 0;
const PAGE = 65536;

const sharedMemory = (pages) => new WebAssembly.Memory({ initial: pages, maximum: pages, shared: true });

/// Compiles kernel.wasm (its URL relative to the page). Resolves to the engine the next regions
/// use: 'wasm' or 'js' (no kernel.wasm, no shared memory; the console says why).
export async function loadEngine(url = 'kernel.wasm') {
  try {
    if (globalThis.crossOriginIsolated === false) throw new Error('the page is not cross-origin isolated');
    const response = await fetch(url);
    if (!response.ok) throw new Error(`${url}: ${response.status}`);
    wasmModule = await WebAssembly.compile(await response.arrayBuffer());
    // The module's own memory (its stack) ends at __heap_base: read it from a throwaway instance.
    heapBase = new WebAssembly.Instance(wasmModule, { env: { memory: sharedMemory(16) } }).exports.__heap_base.value;
  } catch (e) {
    wasmModule = null;
    console.info(`the page's frames run in JavaScript (${e.message})`);
  }
  return engine();
}
export const engine = () => (wasmModule ? 'wasm' : 'js');

/// A new instance's memory, laid out before the instance exists: reserve(bytes) gives an offset
/// (8-byte aligned); instantiate() then makes the instance with room for everything reserved:
/// { exports, memory, buffer }. Null without kernel.wasm.
export function wasmLayout() {
  if (!wasmModule) return null;
  let at = heapBase;
  return {
    reserve(bytes) {
      at = (at + 7) & ~7;
      at += bytes;
      return at - bytes;
    },
    instantiate() {
      const memory = sharedMemory(Math.ceil(at / PAGE) + 1);
      const instance = new WebAssembly.Instance(wasmModule, { env: { memory } });
      return { exports: instance.exports, memory, buffer: memory.buffer };
    },
  };
}

/// One frame's steps on two threads: run(step) evaluates the page's part of a step of
/// page_part() (web/wasm/kernel.cpp) while the worker evaluates the other, and returns when both
/// are done; until the worker is ready, or without workers, the page evaluates the whole step.
/// `args`: page_part()'s pointers (the kernel, the transforms, the result, the drawn normals or
/// 0); `control`: 16 bytes reserved in the instance's memory for the handshake (Int32: the
/// step's number, the step, the number of the step the worker finished); `stackTop`: the end of
/// an area reserved for the worker's stack (each instance has its own stack pointer, and the
/// page's stack is the module's own, below __heap_base). `worker` false: the page's thread alone
/// (a corrected kernel's frames, while the server iterates on the cores: web/kernel.js).
export class FrameThreads {
  constructor(instance, args, control, stackTop, worker = true) {
    Object.assign(this, { exports: instance.exports, args, ready: false, worker: null });
    this.control = new Int32Array(instance.buffer, control, 4);
    if (!worker || typeof Worker === 'undefined' || (globalThis.navigator?.hardwareConcurrency ?? 1) < 2) return;
    try {
      this.worker = new Worker(new URL('kernel_worker.js', import.meta.url), { type: 'module' });
    } catch (e) {
      console.info(`the page's frames run on one thread (${e.message})`);
      return;
    }
    this.worker.onmessage = () => { this.ready = true; };
    this.worker.onerror = (e) => { console.warn(`frame worker: ${e.message}; one thread from now on`); this.stop(); };
    this.worker.postMessage({ module: wasmModule, memory: instance.memory, args, control, stackTop });
  }
  get threads() { return this.ready ? 2 : 1; }
  /// `single`: the page's thread alone (the benchmark compares).
  run(step, single = false) {
    const { exports: w, args, control: c } = this;
    if (!this.ready || single) {
      w.page_part(...args, step, 0, 1);
      return;
    }
    Atomics.store(c, 1, step);
    const number = Atomics.add(c, 0, 1) + 1;
    Atomics.notify(c, 0);
    w.page_part(...args, step, 0, 2);
    // The worker's half takes as long as ours: wait for it here (the page's thread may not block).
    const start = performance.now();
    for (let spins = 1; Atomics.load(c, 2) !== number; ++spins) {
      if ((spins & 1023) === 0 && performance.now() - start > 1000) {
        console.warn('frame worker: no answer in 1 s; one thread from now on');
        this.stop();
        w.page_part(...args, step, 1, 2);
        return;
      }
    }
  }
  /// Ends the worker (a new region has its own).
  stop() {
    this.ready = false;
    if (!this.worker) return;
    Atomics.store(this.control, 1, -1);
    Atomics.add(this.control, 0, 1);
    Atomics.notify(this.control, 0);
    this.worker.terminate();
    this.worker = null;
  }
}
