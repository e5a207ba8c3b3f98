// The page's side of one worker (src/worker.js): requests with ids, replies routed back by id,
// and cancel = terminate the worker and start a new one (a running study reads no messages, so
// nothing else stops it at once).
import { MSG, FINAL_REPLY, message } from './protocol.js';

/** Rejection reason of requests cut short by terminate(). */
export class Cancelled extends Error {
  constructor() {
    super('cancelled');
    this.name = 'Cancelled';
    this.cancelled = true;
  }
}

export class CoreWorker {
  constructor(url) {
    this.url = url;
    this.nextId = 1;
    this.pending = new Map(); // id -> {resolve, reject, onEvent, final}
    this.busy = 0;
    this.start();
  }

  start() {
    this.worker = new Worker(this.url, { type: 'module' });
    this.worker.onmessage = (e) => this.receive(e.data);
    // A worker that cannot start (its module or the wasm glue failed to load) reports here,
    // not with a message: fail what is waiting with the reason.
    this.worker.onerror = (e) => {
      if (e && typeof e.preventDefault === 'function') e.preventDefault();
      const why = (e && e.message) || 'the worker failed to start (is mcplay_web.mjs beside core.js?)';
      this.failAll(new Error(why));
    };
    this.worker.onmessageerror = () => this.failAll(new Error('a worker message could not be read'));
    this.loaded = this.request(MSG.LOAD, {});
    this.loaded.catch(() => {});
  }

  receive(data) {
    const { id, type, payload } = data || {};
    const p = this.pending.get(id);
    if (!p) return;
    if (type === MSG.ERROR) {
      this.settle(id);
      const err = new Error(payload && payload.message ? payload.message : 'worker error');
      Object.assign(err, payload || {});
      p.reject(err);
    } else if (type === p.final) {
      this.settle(id);
      p.resolve(payload);
    } else if (p.onEvent) {
      p.onEvent(type, payload);
    }
  }

  settle(id) {
    this.pending.delete(id);
    this.busy = this.pending.size;
  }

  /** Sends a request; resolves with the payload of its final reply (protocol.FINAL_REPLY);
   *  onEvent(type, payload) receives the replies before it (LEVEL for a run). */
  request(type, payload, onEvent = null) {
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      this.pending.set(id, { resolve, reject, onEvent, final: FINAL_REPLY[type] });
      this.busy = this.pending.size;
      this.worker.postMessage(message(id, type, payload));
    });
  }

  failAll(err) {
    const all = [...this.pending.values()];
    this.pending.clear();
    this.busy = 0;
    for (const p of all) p.reject(err);
  }

  /** Stops the worker now (whatever it computes) and starts a fresh one. */
  restart() {
    this.worker.terminate();
    this.failAll(new Cancelled());
    this.start();
  }

  terminate() {
    this.worker.terminate();
    this.failAll(new Cancelled());
  }
}
