/**
 * The argument checks of the public functions that do not go through the core (measure, gpu,
 * webgpu): one rule per kind of argument, each throwing GcsError('INVALID_ARGUMENT' | 'OUT_OF_RANGE')
 * with the function's name, the argument's name and the value as given. They run once per call, at
 * the top, before anything is allocated; none of them allocates for a valid argument.
 */
import { asGiven, GcsError } from './errors.js';

/** Numbers: an array or a typed array (not a DataView, not an array-like object). */
export function checkNumbers(value: unknown, name: string, fn: string): void {
  if (Array.isArray(value) || (ArrayBuffer.isView(value) && !(value instanceof DataView))) return;
  throw new GcsError('INVALID_ARGUMENT', `${fn}: ${name} must be an array or a typed array of numbers; got ${asGiven(value)}`);
}

/** A list: an array (of anything). */
export function checkList(value: unknown, name: string, fn: string): void {
  if (!Array.isArray(value)) throw new GcsError('INVALID_ARGUMENT', `${fn}: ${name} must be an array; got ${asGiven(value)}`);
}

/** A whole number from `min` to `max`. */
export function checkCount(value: unknown, name: string, fn: string, max: number, min = 0): void {
  if (typeof value !== 'number' || !Number.isInteger(value))
    throw new GcsError('INVALID_ARGUMENT', `${fn}: ${name} must be a whole number (${min} to ${max}); got ${asGiven(value)}`);
  if (value < min || value > max) throw new GcsError('OUT_OF_RANGE', `${fn}: ${name} must be ${min} to ${max}; got ${value}`);
}

/** A finite number. */
export function checkFinite(value: unknown, name: string, fn: string): void {
  if (typeof value !== 'number' || !Number.isFinite(value))
    throw new GcsError('INVALID_ARGUMENT', `${fn}: ${name} must be a finite number; got ${asGiven(value)}`);
}

/** A string. */
export function checkString(value: unknown, name: string, fn: string): void {
  if (typeof value !== 'string') throw new GcsError('INVALID_ARGUMENT', `${fn}: ${name} must be a string; got ${asGiven(value)}`);
}

/** A function. */
export function checkFunction(value: unknown, name: string, fn: string): void {
  if (typeof value !== 'function') throw new GcsError('INVALID_ARGUMENT', `${fn}: ${name} must be a function; got ${asGiven(value)}`);
}

/** An object (not null, not an array, not a function): a record of fields, a class instance. */
export function checkObject(value: unknown, name: string, fn: string): void {
  if (value === null || typeof value !== 'object' || Array.isArray(value))
    throw new GcsError('INVALID_ARGUMENT', `${fn}: ${name} must be an object; got ${asGiven(value)}`);
}

/** An options object: absent, or a plain object (a prototype of Object.prototype or null). */
export function checkOptionsObject(value: unknown, name: string, fn: string): void {
  if (value === undefined) return;
  const proto = value !== null && typeof value === 'object' ? Object.getPrototypeOf(value) : undefined;
  if (proto !== Object.prototype && proto !== null)
    throw new GcsError('INVALID_ARGUMENT', `${fn}: ${name} must be an options object; got ${asGiven(value)}`);
}

/** An object whose `fields` are arrays or typed arrays of numbers. */
export function checkNumberFields(value: unknown, name: string, fn: string, fields: readonly string[]): void {
  checkObject(value, name, fn);
  for (const field of fields) checkNumbers((value as Record<string, unknown>)[field], `${name}.${field}`, fn);
}

/** An object with the methods `methods` (a rig, a deformer, a material: told by what it can do). */
export function checkMethods(value: unknown, name: string, fn: string, methods: readonly string[]): void {
  checkObject(value, name, fn);
  for (const method of methods)
    if (typeof (value as Record<string, unknown>)[method] !== 'function')
      throw new GcsError('INVALID_ARGUMENT', `${fn}: ${name} must have a ${method} method; got ${asGiven(value)} without one`);
}

/** The number arrays of a RigInput. */
export const RIG_INPUT_FIELDS = ['positions', 'indices', 'joints', 'weights', 'parents', 'inverseBindMatrices'] as const;

/** A RigInput: an object whose positions, indices, joints, weights, parents and inverse bind matrices are number arrays. */
export function checkRigInput(value: unknown, name: string, fn: string): void {
  checkNumberFields(value, name, fn, RIG_INPUT_FIELDS);
}

/** A three.js material (isMaterial true). */
export function checkMaterial(value: unknown, name: string, fn: string): void {
  if (value === null || typeof value !== 'object' || (value as { isMaterial?: unknown }).isMaterial !== true)
    throw new GcsError('INVALID_ARGUMENT', `${fn}: ${name} must be a three.js material; got ${asGiven(value)}`);
}
