// Property names a glTF file may not use: those every JavaScript object already has
// (`__proto__`, `constructor`, `toString`, …). The loaders read a file's keys into plain objects
// and look names up in tables (three's GLTFLoader maps attribute names through one,
// @gltf-transform keeps attributes and extensions by name), so such a key reaches a prototype:
// `__proto__` replaces an object's prototype, `constructor` finds a function where a name was
// expected ("prevRef.dispose is not a function"). No glTF needs them: the file is refused.

/** Names on Object.prototype (own names, so `__proto__` too). */
const RESERVED = new Set(Object.getOwnPropertyNames(Object.prototype));

/** The first key of `json` that is a reserved name, and its JSON path; null when none. Iterative: any depth. */
export function reservedKey(json: unknown): { key: string; path: string } | null {
  const stack: [unknown, string][] = [[json, '']];
  while (stack.length) {
    const [value, path] = stack.pop()!;
    if (!value || typeof value !== 'object') continue;
    if (Array.isArray(value)) {
      for (let i = value.length - 1; i >= 0; i--) if (value[i] && typeof value[i] === 'object') stack.push([value[i], `${path}/${i}`]);
      continue;
    }
    for (const key of Object.keys(value)) {
      if (RESERVED.has(key)) return { key, path: `${path}/${key}` };
      const child = (value as Record<string, unknown>)[key];
      if (child && typeof child === 'object') stack.push([child, `${path}/${key}`]);
    }
  }
  return null;
}
