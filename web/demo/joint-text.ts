// What the joint close-up says when a character has no knee or elbow to bend.

/**
 * Why a character has no joint to bend, in one short sentence: its notes once each, "no knee or
 * elbow found" said once (the notes of findHinges end with it already).
 */
export function noJointMessage(name: string, notes: readonly string[]): string {
  const FOUND = 'no knee or elbow found';
  const why = [...new Set(notes.map((n) => n.replace(new RegExp(`:?\\s*${FOUND}$`), '').trim()).filter(Boolean))].join('; ');
  return `${name}: ${FOUND}${why ? ` (${why})` : ''}`;
}
