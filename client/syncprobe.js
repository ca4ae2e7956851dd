// Sync probe: measures, from inside the page, how far the mouth drawn on each animation
// frame is from the audio actually heard at that moment. Install it before speaking:
//
//   const probe = await installSyncProbe(client);   // needs client.unlock() to succeed
//   ... speak ...
//   probe.snapshot()  // {rate, block, envStart, env, frames: [[utt, outputTime, mouthSample, lipGap, drawMs]]}
//
// The audio side comes from an AudioWorklet tap (syncprobe-worklet.js) that every source
// passes through; the mouth side from the client's "frame" events, stamped with the
// context time heard at the frame's time (getOutputTimestamp). Matching the tapped
// envelope against the utterance's own audio (bench/clientsync.py) then gives the context
// time at which sample 0 was really heard, and from it the lag of every drawn frame.

export async function installSyncProbe(client) {
  if (!(await client.unlock())) throw new Error("sync probe: audio is not running");
  const ctx = client.ctx;
  await ctx.audioWorklet.addModule(new URL("./syncprobe-worklet.js", import.meta.url));
  const node = new AudioWorkletNode(ctx, "lipclock-sync-tap",
                                    { numberOfInputs: 1, numberOfOutputs: 1, outputChannelCount: [1] });
  node.connect(ctx.destination);
  client.tap = node;
  const probe = { rate: ctx.sampleRate, block: 0, envStart: null, env: [], frames: [] };
  node.port.onmessage = (e) => {
    const { startFrame, block, env } = e.data;
    probe.block = block;
    if (probe.envStart === null) probe.envStart = startFrame;
    const at = Math.round((startFrame - probe.envStart) / block);
    for (let i = 0; i < env.length; i++) probe.env[at + i] = env[i];
  };
  client.addEventListener("frame", (e) => {
    const d = e.detail;
    if (d.utterance === null || d.audioSample === null || d.outputTime === null) return;
    probe.frames.push([d.utterance, d.outputTime, d.mouthSample, d.lipGap, d.drawMs]);
  });
  probe.snapshot = () => ({ rate: probe.rate, block: probe.block, envStart: probe.envStart,
                            env: Array.from(probe.env, (v) => v ?? 0), frames: probe.frames });
  return probe;
}
