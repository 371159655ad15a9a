// The page's scheduling of its frame requests, in node without a browser: the Coalescer
// (web/picking.js: at most one request in flight, or two when one overtakes, answers received in
// the order sent) and the Relaxer (web/drag_frames.js: the relax steps' budgets, none sent while
// one is in flight). Requests are answered by hand, in the order each case needs.
//
//   node web/tests/frames.mjs
import assert from 'node:assert/strict';
import test from 'node:test';
import { Relaxer } from '../drag_frames.js';
import { Coalescer } from '../picking.js';

/// send() that records each request and returns a promise the test settles: answer(i, value) or
/// fail(i).
function manualSend() {
  const sent = [];
  const send = (request) => new Promise((resolve, reject) => sent.push({ request, resolve, reject }));
  return { sent, send, answer: (i, value) => sent[i].resolve(value), fail: (i) => sent[i].reject(new Error('refused')) };
}
const settle = () => new Promise((resolve) => setTimeout(resolve, 0));

test('without overtaking, one request is in flight and a newer one replaces the waiting one', async () => {
  const s = manualSend(), received = [];
  const c = new Coalescer(s.send, (result, request) => received.push([request.id, result]));
  c.submit({ id: 1 });
  c.submit({ id: 2 });
  c.submit({ id: 3 }); // replaces 2
  await settle();
  assert.deepEqual(s.sent.map((x) => x.request.id), [1]);
  s.answer(0, 'a');
  await settle();
  assert.deepEqual(s.sent.map((x) => x.request.id), [1, 3]);
  s.answer(1, 'c');
  await c.idle();
  assert.deepEqual(received, [[1, 'a'], [3, 'c']]);
  assert.equal(c.busy, false);
});

test('an overtaking request is sent at once, and the answers are received in the order sent', async () => {
  const s = manualSend(), received = [];
  const overtakes = (waiting, inFlight) => inFlight.relax && !waiting.relax;
  const c = new Coalescer(s.send, (result, request) => received.push([request.id, result]), overtakes);
  c.submit({ id: 1, relax: true });
  c.submit({ id: 2 }); // a move: overtakes the relax step
  assert.deepEqual(s.sent.map((x) => x.request.id), [1, 2]);
  assert.deepEqual(c.sent.map((r) => r.id), [1, 2]);
  c.submit({ id: 3 }); // two in flight: waits
  c.submit({ id: 4 }); // and is replaced
  assert.equal(s.sent.length, 2);
  s.answer(1, 'b'); // the move's answer first
  await settle();
  assert.deepEqual(received, []); // held until the relax step's
  s.answer(0, 'a');
  await settle();
  assert.deepEqual(received, [[1, 'a'], [2, 'b']]);
  assert.deepEqual(s.sent.map((x) => x.request.id), [1, 2, 4]);
  s.answer(2, 'd');
  await c.idle();
  assert.deepEqual(received, [[1, 'a'], [2, 'b'], [4, 'd']]);
});

test('a refused request is dropped and the ones behind it are received', async () => {
  const s = manualSend(), received = [];
  const c = new Coalescer(s.send, (result, request) => received.push(request.id), () => true);
  c.submit({ id: 1 });
  c.submit({ id: 2 });
  s.fail(1); // the overtaking one fails before the first is answered
  await settle();
  s.answer(0, 'a');
  await c.idle();
  assert.deepEqual(received, [1]);
  c.submit({ id: 3 });
  s.fail(2);
  await c.idle();
  c.submit({ id: 4 });
  s.answer(3, 'd');
  await c.idle();
  assert.deepEqual(received, [1, 4]);
});

test('the relax steps: a release starts at once with its own budget, then the longest', async () => {
  const steps = [];
  let inFlight = false;
  const relaxer = new Relaxer((budget) => steps.push(budget), () => inFlight);
  relaxer.moved(performance.now());
  relaxer.released(performance.now());
  relaxer.soon();
  await settle();
  assert.deepEqual(steps, [Relaxer.RELEASE_BUDGET_MS]);
  relaxer.soon();
  await settle();
  assert.deepEqual(steps, [Relaxer.RELEASE_BUDGET_MS, Relaxer.BUDGET_MAX_MS]);
  // A step in flight: no other is sent; its answer asks again (soon()).
  inFlight = true;
  relaxer.soon();
  await settle();
  assert.equal(steps.length, 2);
  assert.equal(relaxer.idle, true);
  inFlight = false;
  // A move starts over: after the pause, the shortest budget.
  relaxer.moved(performance.now());
  relaxer.soon();
  await settle();
  assert.equal(steps.length, 2); // the pointer has not rested yet
  await new Promise((resolve) => setTimeout(resolve, Relaxer.PAUSE_MS + 30));
  assert.deepEqual(steps.slice(2), [Relaxer.BUDGET_MS]);
  relaxer.cancel();
});
