// The second thread of the page's frames (web/engine.js, FrameThreads): an instance of
// kernel.wasm on the region's shared memory that evaluates part 1 of 2 of each step the page
// asks for, until the page asks for step −1 or ends the worker.
const SPIN_MS = 100;

onmessage = ({ data }) => {
  const { module, memory, args, control, stackTop } = data;
  const w = new WebAssembly.Instance(module, { env: { memory } }).exports;
  w.__stack_pointer.value = stackTop; // a stack of its own in the shared memory
  const c = new Int32Array(memory.buffer, control, 4);
  let seen = Atomics.load(c, 0);
  postMessage('ready');
  for (;;) {
    // The steps of a frame follow each other within microseconds, and a drag's frames come
    // every display frame: look for the next step for up to SPIN_MS before sleeping (waking up
    // costs from tens of microseconds to milliseconds when another process holds the core).
    const start = performance.now();
    for (let spins = 1; Atomics.load(c, 0) === seen; ++spins)
      if ((spins & 1023) === 0 && performance.now() - start > SPIN_MS) break;
    Atomics.wait(c, 0, seen); // returns at once when the page has already asked
    seen = Atomics.load(c, 0);
    const step = Atomics.load(c, 1);
    if (step < 0) return;
    w.page_part(...args, step, 1, 2);
    Atomics.store(c, 2, seen);
  }
};
