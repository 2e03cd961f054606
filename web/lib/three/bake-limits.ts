// What bakeClip may allocate, checked before it allocates: a clip's frame count × joints × 16
// floats, from a finite duration and frame rate.
import type * as THREE from 'three';
import { asGiven, GcsError } from '../errors.js';

/** Most floats a baked clip holds (1 GiB): a 10-minute clip of 100 joints at 60 fps is 58 M. */
export const MAX_BAKED_FLOATS = 2 ** 28;

/** The frame count bakeClip samples `clip` at `fps` into, for `jointCount` joints; GcsError for what cannot be baked. */
export function bakedFrameCount(clip: THREE.AnimationClip, fps: unknown, jointCount: number): number {
  if (!clip || typeof clip !== 'object' || !(clip as { isAnimationClip?: boolean }).isAnimationClip && !Array.isArray((clip as { tracks?: unknown }).tracks))
    throw new GcsError('INVALID_ARGUMENT', `bakeClip needs a THREE.AnimationClip; got ${asGiven(clip)}`);
  if (typeof fps !== 'number' || !(fps > 0 && fps <= 1000)) throw new GcsError('OUT_OF_RANGE', `fps must be a number in (0, 1000]; got ${asGiven(fps)}`);
  const duration = clip.duration;
  if (typeof duration !== 'number' || !Number.isFinite(duration) || duration < 0)
    throw new GcsError('OUT_OF_RANGE', `the clip '${clip.name}' lasts ${asGiven(duration)} s: a clip to bake lasts a finite, non-negative time`);
  const frames = Math.max(1, Math.round(duration * fps));
  if (frames * jointCount * 16 > MAX_BAKED_FLOATS)
    throw new GcsError('OUT_OF_RANGE', `baking '${clip.name}' (${duration} s at ${fps} fps, ${jointCount} joints) needs ${frames} frames of ${jointCount * 16} floats, more than ${MAX_BAKED_FLOATS} floats (1 GiB): bake at a lower fps or a part of the clip`);
  return frames;
}
