// The methods the report, metrics and tests compare, built by name, and a build failure as data.
import { asGiven, GcsError } from '../errors.js';
import type { Deformer, Rig } from '../index.js';

/**
 * The methods the report, metrics and tests compare: GCS with the weights criterion (the default),
 * plain (its stepped level of detail, smooth: false), the paper's Y criterion and the axial variant (influence width 1), the classic
 * cross-section model, LBS and DQS.
 */
export type MethodName = 'gcs' | 'gcs-plain' | 'gcs-y' | 'gcs-axial' | 'classic' | 'lbs' | 'dqs';
/** Every method the measures know, in the order the tables print them. */
export const METHODS: MethodName[] = ['gcs', 'gcs-plain', 'gcs-y', 'gcs-axial', 'classic', 'lbs', 'dqs'];
/** How the tables name each method. */
export const METHOD_LABELS: Record<MethodName, string> = {
  gcs: 'GCS (weights, default)', 'gcs-plain': 'GCS plain (weights, stepped)', 'gcs-y': 'GCS paper (Y)', 'gcs-axial': 'GCS paper (axial)',
  classic: 'classic', lbs: 'LBS', dqs: 'DQS',
};

/** Settings of `buildMethod`: the GCS section count and the classic model's density. */
export interface BuildSettings {
  /** GCS sections (default 6). */
  sections?: number;
  /** Classic contours per part (default 25). */
  contours?: number;
  /** Classic rays per contour (default 20). */
  rays?: number;
}

/** Builds a deformer by method name. */
export function buildMethod(rig: Rig, method: MethodName, settings: BuildSettings = {}): Deformer {
  switch (method) {
    case 'gcs': return rig.buildGcs({ sections: settings.sections });
    case 'gcs-plain': return rig.buildGcs({ sections: settings.sections, smooth: false });
    case 'gcs-y': return rig.buildGcs({ sections: settings.sections, criterion: 'y' });
    case 'gcs-axial': return rig.buildGcs({ sections: settings.sections, criterion: 'axial' });
    case 'classic': return rig.buildClassic({ contours: settings.contours, rays: settings.rays });
    case 'lbs': return rig.buildLbs();
    case 'dqs': return rig.buildDqs();
  }
}

/** A build failure as data: the GcsError code and message (e.g. a method not in this binary). */
export function errorInfo(e: unknown): {
  /** The GcsError's code, or 'ERROR' for any other exception. */
  code: string;
  /** Its sentence. */
  message: string;
} {
  if (e instanceof GcsError) return { code: e.code, message: e.message };
  if (e instanceof Error) return { code: 'ERROR', message: e.message };
  let message: string;
  try { message = String(e); } catch { message = asGiven(e); } // an object whose toString or toPrimitive throws
  return { code: 'ERROR', message };
}
