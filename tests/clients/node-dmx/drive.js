// Test-only client: node-dmx's enttec-usb-dmx-pro driver (npm dmx 0.25.1, drivers/enttec-usb-dmx-pro.js, on
// serialport 11) streams one universe to the port given, at its own rate (dmx_speed, 40 frames/s by default).
//   node drive.js PORT SCENE...   each SCENE is JSON {"channel": level, ...} with 1-based DMX channels
// It applies the first scene once the port is open, the next on each SIGUSR1, and prints "scene N" after each;
// the test reads the simulator's truth in between. It exits on SIGTERM, or with 1 if the port fails.
'use strict';
const DMX = require('dmx');

const [port, ...scenes] = process.argv.slice(2);
if (!port || scenes.length === 0) {
  console.error('usage: node drive.js PORT SCENE...');
  process.exit(2);
}

const dmx = new DMX();
const universe = dmx.addUniverse('lab', 'enttec-usb-dmx-pro', port);
let next = 0;
const apply = () => {
  if (next >= scenes.length) return;
  dmx.update('lab', JSON.parse(scenes[next]));
  console.log(`scene ${next}`);
  next += 1;
};
// The driver only console.warn()s an open error and then never streams: make that a failure the test sees.
universe.dev.on('error', (err) => {
  console.log(`error ${err.message}`);
  process.exit(1);
});
universe.dev.on('open', apply);
process.on('SIGUSR1', apply);
process.on('SIGTERM', () => {
  universe.stop();
  universe.close(() => process.exit(0));
});
