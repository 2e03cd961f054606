// The page's own messages: the error banner (one sentence, dismissable), the "building…" status,
// and the sentence an error gives the user.
import { GcsError } from '../lib/index.js';
import { GltfError } from './load-gltf.js';
import { dom } from './state.js';

/** An error whose message is meant for the page as it is. */
export class DemoError extends Error {}

export function showMessage(text: string): void {
  dom.messageText.textContent = text;
  dom.message.hidden = false;
  console.warn('[gcs-skin demo]', text);
}

export function clearMessage(): void {
  dom.message.hidden = true;
  dom.messageText.textContent = '';
}

/** The message on the page, '' when none. */
export function shownMessage(): string {
  return dom.message.hidden ? '' : dom.messageText.textContent ?? '';
}

export function showStatus(text: string): void {
  dom.status.textContent = text;
  dom.status.hidden = false;
}

export function hideStatus(): void {
  dom.status.hidden = true;
}

export function describeError(e: unknown): string {
  if (e instanceof GcsError || e instanceof GltfError) return `${e.message} (${e.code})`;
  if (e instanceof Error) return e.message;
  return String(e);
}

/** Lets the browser paint (the "building…" status) before the next synchronous step. */
export function yieldToPage(): Promise<void> {
  return new Promise((resolve) => {
    let done = false;
    const finish = () => { if (!done) { done = true; resolve(); } };
    requestAnimationFrame(() => setTimeout(finish, 0));
    setTimeout(finish, 60); // rAF stalls in hidden tabs
  });
}
