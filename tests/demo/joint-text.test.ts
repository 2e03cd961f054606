// The joint close-up's message for a character without knees or elbows (web/demo/joint-text.ts).
import { expect, test } from 'vitest';
import { noJointMessage } from '../../web/demo/joint-text.js';

test('"no knee or elbow found" said once, each note once', () => {
  const note = 'one mirrored pair of limbs only (legs and arms need two, with skin on this mesh): no knee or elbow found';
  const message = noJointMessage('RobotExpressive.glb', [note, note]);
  expect(message).toBe('RobotExpressive.glb: no knee or elbow found (one mirrored pair of limbs only (legs and arms need two, with skin on this mesh))');
  expect(message.match(/no knee or elbow found/g)).toHaveLength(1);
  expect(noJointMessage('x.glb', [])).toBe('x.glb: no knee or elbow found');
  expect(noJointMessage('x.glb', ['the limbs reach nowhere: no knee or elbow found', 'forward is a guess']))
    .toBe('x.glb: no knee or elbow found (the limbs reach nowhere; forward is a guess)');
});
