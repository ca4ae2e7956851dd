// AudioWorklet for the sync probe (syncprobe.js): passes the audio through unchanged and
// reports what actually flowed, as a mean-absolute envelope per block of BLOCK frames,
// stamped with the context frame where each batch starts. The context clock is the one
// getOutputTimestamp() maps to the speakers, so the page can tell which utterance sample
// was heard at any moment without trusting the client's own bookkeeping.

const BLOCK = 16;          // frames per envelope value (0.33 ms at 48 kHz)
const BATCH = 64;          // render quanta per message (~170 ms at 48 kHz)

class SyncTap extends AudioWorkletProcessor {
  constructor() {
    super();
    this.values = [];
    this.start = null;
    this.quanta = 0;
  }

  process(inputs, outputs) {
    const input = inputs[0];
    const out = outputs[0];
    const x = input && input.length ? input[0] : null;
    const n = out[0].length;
    for (let c = 0; c < out.length; c++) {
      if (x) out[c].set(input[c] || x); else out[c].fill(0);
    }
    if (this.start === null) this.start = currentFrame;
    for (let i = 0; i < n; i += BLOCK) {
      let sum = 0;
      if (x) for (let j = i; j < i + BLOCK && j < n; j++) sum += Math.abs(x[j]);
      this.values.push(sum / BLOCK);
    }
    if (++this.quanta >= BATCH) {
      const env = Float32Array.from(this.values);
      this.port.postMessage({ startFrame: this.start, block: BLOCK, env }, [env.buffer]);
      this.values = [];
      this.start = null;
      this.quanta = 0;
    }
    return true;
  }
}

registerProcessor("lipclock-sync-tap", SyncTap);
