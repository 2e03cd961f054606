// The numbers the core gives its deformer kinds and statistics (gcs_skin.h GcsDeformerKind,
// GcsStat); tests/lib/boundary.test.ts checks them against the header. The public enums (CRITERIA,
// CLASSIC_REASONS) are in index.ts, ordered by their numbers likewise.

/** GcsDeformerKind: index = the core's number. */
export const DEFORMER_KINDS = ['gcs', 'classic', 'lbs', 'dqs'] as const;

/** GcsStat: the query numbers of gcs_deformer_stat. */
export const STATS = { sections: 0, parts: 1, adjustedShare: 2, adjustedSections: 3 } as const;
