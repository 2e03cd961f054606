/**
 * The GCS vertex stage in GLSL, for WebGLRenderer: three.js's skinning chunks of a built-in
 * material replaced by GCS's (patched through onBeforeCompile, webgl-materials.ts). The same maths
 * as the TSL function (tsl.ts), from the same layout constants (layout.ts); docs/gpu.md.
 */
import { checkString } from '../arguments.js';
import { asGiven, GcsError } from '../errors.js';
import {
  ALMOST_EQUAL_TRACE, ALMOST_EQUAL_TRACE3, BLEND_ATTRIBUTE, BLEND_THIRD_ATTRIBUTE, COLLAPSED, GPU_TEXELS_PER_JOINT,
  DQS_TEXELS_PER_JOINT, GPU_NODE_TEXTURES, GPU_TEXELS_PER_SECTION, LENGTH_FIX, RIGID_JOINT_TOLERANCE, NEAR_TRACE, NEAR_TRACE3, SECTION_ATTRIBUTE, UNIFORM_SCALE_TOLERANCE, tableTexelsPerSection, INFLUENCE_ATTRIBUTES, WEIGHT_ATTRIBUTES, type GpuMethod, type GpuPath, type TableSlots,
} from './layout.js';

/** GLSL's spelling of a float constant (always with a decimal point or exponent). */
const f = (x: number): string => (Number.isInteger(x) ? x.toFixed(1) : String(x));

/** Both paths: where instance 0's texels start, texels per instance, the static per-vertex section data. */
const COMMON_PARS = /* glsl */ `
uniform int gcsBase;
uniform int gcsStride;
#ifdef GCS_SMOOTH
attribute vec3 ${BLEND_ATTRIBUTE};
attribute vec2 ${BLEND_THIRD_ATTRIBUTE};
#else
attribute float ${SECTION_ATTRIBUTE};
#endif
`;

const PARS = /* glsl */ `
uniform highp sampler2D gcsSections;${COMMON_PARS}
void gcsRows( const in int section, out vec4 r0, out vec4 r1, out vec4 r2 ) {
	int i = gcsBase + section * ${GPU_TEXELS_PER_SECTION};
	#ifdef USE_INSTANCING
	i += gl_InstanceID * gcsStride;
	#endif
	int w = textureSize( gcsSections, 0 ).x;
	r0 = texelFetch( gcsSections, ivec2( i % w, i / w ), 0 );
	i += 1; r1 = texelFetch( gcsSections, ivec2( i % w, i / w ), 0 );
	i += 1; r2 = texelFetch( gcsSections, ivec2( i % w, i / w ), 0 );
}
// Rows of the cofactor matrix of the 3×3 part (rows a, b, c), divided by its largest entry first
// (no overflow under ×1e20 scales): the normal matrix up to a positive factor. Smooth mode blends
// two of them, so each is brought to the CPU's scale: divided by |det|^(2/3) (a rotation times a
// uniform scale gives back the rotation).
void gcsNormalRows( vec4 r0, vec4 r1, vec4 r2, const in bool unitScale, out vec3 n0, out vec3 n1, out vec3 n2 ) {
	vec3 a = r0.xyz, b = r1.xyz, c = r2.xyz;
	vec3 m = max( max( abs( a ), abs( b ) ), abs( c ) );
	float big = max( max( m.x, m.y ), m.z );
	if ( big > 0.0 ) { a /= big; b /= big; c /= big; }
	n0 = cross( b, c ); n1 = cross( c, a ); n2 = cross( a, b );
	if ( unitScale ) {
		float det = abs( dot( a, n0 ) );
		if ( det > ${f(COLLAPSED)} ) { float k = 1.0 / pow( det, 2.0 / 3.0 ); n0 *= k; n1 *= k; n2 *= k; }
	}
}
vec3 gcsTurn( const in vec3 v, const in vec3 n0, const in vec3 n1, const in vec3 n2 ) {
	vec3 t = vec3( dot( n0, v ), dot( n1, v ), dot( n2, v ) );
	float l = length( t );
	return l > 0.0 ? t / l : v;
}
`;

/** Per vertex, once: the blended rows of its affine 3×4 and the rows of its normal matrix. */
const BASE = /* glsl */ `
	vec4 gcsR0, gcsR1, gcsR2;
	vec3 gcsN0, gcsN1, gcsN2;
	{
		#ifdef GCS_SMOOTH
		vec4 a0, a1, a2, b0, b1, b2;
		int sa = int( ${BLEND_ATTRIBUTE}.x + 0.5 ), sc = int( ${BLEND_THIRD_ATTRIBUTE}.x + 0.5 );
		gcsRows( sa, a0, a1, a2 );
		gcsRows( int( ${BLEND_ATTRIBUTE}.y + 0.5 ), b0, b1, b2 );
		float f = ${BLEND_ATTRIBUTE}.z;
		gcsR0 = a0 + f * ( b0 - a0 ); gcsR1 = a1 + f * ( b1 - a1 ); gcsR2 = a2 + f * ( b2 - a2 );
		vec3 p0, p1, p2, q0, q1, q2;
		gcsNormalRows( a0, a1, a2, true, p0, p1, p2 );
		gcsNormalRows( b0, b1, b2, true, q0, q1, q2 );
		gcsN0 = p0 + f * ( q0 - p0 ); gcsN1 = p1 + f * ( q1 - p1 ); gcsN2 = p2 + f * ( q2 - p2 );
		if ( sc != sa ) {
			// A three-joint lattice cell: + g·(C − A).
			float g = ${BLEND_THIRD_ATTRIBUTE}.y;
			vec4 c0, c1, c2;
			gcsRows( sc, c0, c1, c2 );
			gcsR0 += g * ( c0 - a0 ); gcsR1 += g * ( c1 - a1 ); gcsR2 += g * ( c2 - a2 );
			gcsNormalRows( c0, c1, c2, true, q0, q1, q2 );
			gcsN0 += g * ( q0 - p0 ); gcsN1 += g * ( q1 - p1 ); gcsN2 += g * ( q2 - p2 );
		}
		#else
		gcsRows( int( ${SECTION_ATTRIBUTE} + 0.5 ), gcsR0, gcsR1, gcsR2 );
		gcsNormalRows( gcsR0, gcsR1, gcsR2, false, gcsN0, gcsN1, gcsN2 );
		#endif
	}
`;

/** Normals and tangents, each turned by `turn` (the GLSL call on that vector). */
const turned = (turn: (v: string) => string) => /* glsl */ `
	objectNormal = ${turn('objectNormal')};
	#ifdef USE_TANGENT
	objectTangent = ${turn('objectTangent')};
	#endif
`;

const NORMAL = turned((v) => `gcsTurn( ${v}, gcsN0, gcsN1, gcsN2 )`);

const POSITION = /* glsl */ `
	{
		vec4 p = vec4( transformed, 1.0 );
		transformed = vec3( dot( gcsR0, p ), dot( gcsR1, p ), dot( gcsR2, p ) );
	}
`;

// ------------------------------------------------------------ the joint-level path (weights criterion)
// Matrices are GLSL's (column-major); the math is GcsDeformerImpl::sectionTransformsWeights,
// blendPoses and normalMatrix (wasm/src), step for step. It runs once per node and frame in the node
// pass (node-pass.ts: a fragment per output texel, all instances of a crowd in one draw); the vertex
// stage reads the result (NODE_PARS) and blends.

/** How the joint-level path turns a normal or tangent with a normal matrix N. */
const TURN_JOINT = /* glsl */ `
// A normal or tangent as the CPU turns it: blended (smooth) normals are left as they are when both
// sides are rotations less than 2.8° apart, get the cubic length fix when less than 35° apart, else
// are normalised (a vanished one keeps its rest direction); unblended ones are normalised only when
// the scale asks for it.
vec3 gcsTurnJoint( const in vec3 v, const in mat3 N, const in bool near, const in bool almostEqual, const in bool normalise ) {
	vec3 n = N * v;
	if ( almostEqual ) return n;
	if ( near ) { float e = dot( n, n ) - 1.0; return n * ( 1.0 + e * ( ${f(LENGTH_FIX[0])} + ${f(LENGTH_FIX[1])} * e ) ); }
	if ( normalise ) { float l = length( n ); return l > 0.0 ? n / l : v; }
	return n;
}
`;

/** The rotation matrix of a quaternion: the node pass and the vertex stage both build one. */
const ROTATION = /* glsl */ `
// The rotation matrix of a quaternion scaled by k2 = 2 / |q|² (1 for a unit quaternion: k2 = 2).
mat3 gcsRotation( const in vec4 q, const in float k2 ) {
	float xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z, xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
	float wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
	return mat3( 1.0 - k2 * ( yy + zz ), k2 * ( xy + wz ), k2 * ( xz - wy ),
		k2 * ( xy - wz ), 1.0 - k2 * ( xx + zz ), k2 * ( yz + wx ),
		k2 * ( xz + wy ), k2 * ( yz - wx ), 1.0 - k2 * ( xx + yy ) );
}
`;

/** The normal texel of a blended scale part K: the node pass and per-vertex DQS both compute one. */
const NORMAL_TEXEL = /* glsl */ `
// The CPU's normalMatrix as one texel (x, y, 0, flag), from which the vertex stage takes
// N = cof(M·x)·y, M = R·K (cof(R) = R): R·cof(K/s) = R when K is a positive uniform scale s·I (up to
// 1e-4): (1/s, 1, 0, 0); else R·cof(K/kbig)/big, its entries ≤ 1 and normals renormalised:
// (1/kbig, 1/big, 0, −1). A collapsed K (rank ≤ 1) gives N = 0: the normal keeps its rest
// direction (the CPU keeps it rotated; no direction survives such a scale).
vec4 gcsNormalTexel( const in mat3 k ) {
	float s = ( k[ 0 ][ 0 ] + k[ 1 ][ 1 ] + k[ 2 ][ 2 ] ) / 3.0;
	bool uniformScale = s > 0.0;
	for ( int c = 0; c < 3; c ++ ) for ( int i = 0; i < 3; i ++ )
		if ( abs( k[ c ][ i ] - ( c == i ? s : 0.0 ) ) > ${f(UNIFORM_SCALE_TOLERANCE)} * s ) uniformScale = false;
	if ( uniformScale ) return vec4( 1.0 / s, 1.0, 0.0, 0.0 );
	vec3 m = max( max( abs( k[ 0 ] ), abs( k[ 1 ] ) ), abs( k[ 2 ] ) );
	float kbig = max( max( m.x, m.y ), m.z );
	if ( ! ( kbig > ${f(COLLAPSED)} ) ) return vec4( 0.0, 0.0, 0.0, - 1.0 );
	mat3 a = k / kbig;
	mat3 c = mat3( cross( a[ 1 ], a[ 2 ] ), cross( a[ 2 ], a[ 0 ] ), cross( a[ 0 ], a[ 1 ] ) );
	m = max( max( abs( c[ 0 ] ), abs( c[ 1 ] ) ), abs( c[ 2 ] ) );
	float big = max( max( m.x, m.y ), m.z );
	if ( ! ( big > ${f(COLLAPSED)} ) ) return vec4( 0.0, 0.0, 0.0, - 1.0 );
	return vec4( 1.0 / kbig, 1.0 / big, 0.0, - 1.0 );
}
`;

/** Slot k of a section's table (its joint id and weight; the second set past 4); a slot of weight 0 is skipped. */
const TABLE_SLOT = /* glsl */ `
		#if GCS_TABLE_SLOTS > 4
		float id = k < 4 ? joints[ k ] : joints1[ k - 4 ], w = k < 4 ? weights[ k ] : weights1[ k - 4 ];
		#else
		float id = joints[ k ], w = weights[ k ];
		#endif
		if ( ! ( w > 0.0 ) ) continue;`;

/** The joint poses (per frame, the full format): joint j's texels, the rotation of a quaternion, the normal texel of a scale part. */
const NODE_MATHS = /* glsl */ `
uniform highp sampler2D gcsJoints;
vec4 gcsTexel( const in highp sampler2D t, const in int i ) {
	int w = textureSize( t, 0 ).x;
	return texelFetch( t, ivec2( i % w, i / w ), 0 );
}
// The texel after \`at\` in a texture \`w\` wide (one division per joint, not per texel).
ivec2 gcsNextTexel( const in ivec2 at, const in int w ) {
	return at.x + 1 < w ? ivec2( at.x + 1, at.y ) : ivec2( 0, at.y + 1 );
}
// Joint j's texels (from \`base\`, the instance's first): the rows of S_j (translation in w) and its rotation quaternion.
void gcsJointTexels( const in int base, const in int j, out vec4 r0, out vec4 r1, out vec4 r2, out vec4 q ) {
	int i = base + j * ${GPU_TEXELS_PER_JOINT}, w = textureSize( gcsJoints, 0 ).x, y = i / w;
	ivec2 at = ivec2( i - y * w, y );
	r0 = texelFetch( gcsJoints, at, 0 ); at = gcsNextTexel( at, w );
	r1 = texelFetch( gcsJoints, at, 0 ); at = gcsNextTexel( at, w );
	r2 = texelFetch( gcsJoints, at, 0 ); at = gcsNextTexel( at, w );
	q = texelFetch( gcsJoints, at, 0 );
}
${ROTATION}
${NORMAL_TEXEL}`;

/**
 * What the passes read of a joint (node pass, DQS's joint pass; never per vertex): its pose from
 * the full format (gcsJoints) or, on a frame whose every joint is rigid with unit scale
 * (gcsCompactPoses = 1, one uniform for the whole frame), from the compact one (gcsCompactJoints:
 * COMPACT_FLOATS_PER_JOINT floats, 1.5 texels, per joint; gcs_gcs_compute_joint_poses_compact).
 */
const JOINT_POSE = /* glsl */ `
uniform highp sampler2D gcsCompactJoints;
uniform int gcsCompactPoses;
// Joint j's pose: S_j (3×3 part and translation) and its rotation quaternion (x, y, z, w). Compact:
// the smallest three of q (the dropped one's index in the lowest bits of the first two; the dropped
// one positive, ≥ 1/2) and t; S_j = R(q).
void gcsJoint( const in int base, const in int j, out mat3 s, out vec3 t, out vec4 q ) {
	if ( gcsCompactPoses == 1 ) {
		int g = base / ${GPU_TEXELS_PER_JOINT} + j, i = ( 3 * g ) >> 1; // joint g's first texel: its 6 floats start at lane 0 (g even) or 2 (odd)
		vec4 a = gcsTexel( gcsCompactJoints, i ), b = gcsTexel( gcsCompactJoints, i + 1 );
		bool odd = ( g & 1 ) == 1;
		vec3 c = odd ? vec3( a.zw, b.x ) : a.xyz;
		t = odd ? b.yzw : vec3( a.w, b.xy );
		uint dropped = ( floatBitsToUint( c.x ) & 1u ) | ( ( floatBitsToUint( c.y ) & 1u ) << 1 );
		float d = sqrt( max( 1.0 - dot( c, c ), 0.0 ) );
		q = dropped == 0u ? vec4( d, c ) : dropped == 1u ? vec4( c.x, d, c.yz ) : dropped == 2u ? vec4( c.xy, d, c.z ) : vec4( c, d );
		s = gcsRotation( q, 2.0 );
		return;
	}
	vec4 r0, r1, r2;
	gcsJointTexels( base, j, r0, r1, r2, q );
	s = transpose( mat3( r0.xyz, r1.xyz, r2.xyz ) );
	t = vec3( r0.w, r1.w, r2.w );
}
`;

/**
 * The node pass's maths: a node from its joints' parts, as the joint pass wrote them once per joint
 * and frame (DQS_PASS_FRAGMENT: the quaternion, dual part and uniform scale; the rows of K).
 */
const NODE_FROM_PARTS = /* glsl */ `
uniform highp sampler2D gcsJointParts0;
uniform highp sampler2D gcsJointParts1;
uniform highp sampler2D gcsJointParts2;
uniform int gcsJointRow;
// Joint j's scale part K (columns) from its second texel in the joint pass's row \`row\`.
mat3 gcsPartScale( const in float j, const in int row ) {
	ivec2 at = ivec2( int( j ) * ${DQS_TEXELS_PER_JOINT} + 1, row );
	return transpose( mat3( texelFetch( gcsJointParts0, at, 0 ).xyz, texelFetch( gcsJointParts1, at, 0 ).xyz, texelFetch( gcsJointParts2, at, 0 ).xyz ) );
}
// The dual-quaternion blend of up to GCS_TABLE_SLOTS joints (ids in joints, joints1; weights in
// weights, weights1; a slot of weight 0 adds nothing) into x ↦ M x + T and the normal texel N
// (gcsNormalTexel), from their parts in the joint pass's row \`row\`: where every joint is a uniform
// scale, M = s·R (s = Σ w u) and N = (1/s, 1, 0, 0); otherwise K = Σ w K_j applied first, M = R·K.
// With a centre of rotation (w = 1; w = 0: none) the blend's M about it, the centre moved by
// LBS (the joint poses from \`base\`). One joint alone (joints.y < 0) is S_j itself.
// The CPU's blendPoses, step for step.
void gcsBlend( const in int base, const in int row, const in vec4 joints, const in vec4 weights, const in vec4 joints1, const in vec4 weights1,
	const in vec4 centre, out mat3 M, out vec3 T, out vec4 N ) {
	if ( joints.y < 0.0 ) {
		vec4 q;
		gcsJoint( base, int( joints.x ), M, T, q );
		N = gcsNormalTexel( gcsPartScale( joints.x, row ) );
		return;
	}
	vec4 pivot = texelFetch( gcsJointParts0, ivec2( int( joints.x ) * ${DQS_TEXELS_PER_JOINT}, row ), 0 ), br = vec4( 0.0 ), bd = vec4( 0.0 );
	float s = 0.0;
	bool rigid = true; // every joint's K a uniform scale: the blend of scales is s·I
	for ( int k = 0; k < GCS_TABLE_SLOTS; k ++ ) {${TABLE_SLOT}
		ivec2 at = ivec2( int( id ) * ${DQS_TEXELS_PER_JOINT}, row );
		vec4 q = texelFetch( gcsJointParts0, at, 0 );
		float sw = dot( q, pivot ) < 0.0 ? - w : w;
		br += sw * q;
		bd += sw * texelFetch( gcsJointParts1, at, 0 );
		float u = texelFetch( gcsJointParts2, at, 0 ).x;
		s += w * u;
		rigid = rigid && u > 0.0;
	}
	float inv2 = 1.0 / dot( br, br );
	T = ( 2.0 * inv2 ) * ( br.w * bd.xyz - bd.w * br.xyz - cross( bd.xyz, br.xyz ) );
	mat3 R = gcsRotation( br, 2.0 * inv2 );
	if ( rigid ) {
		M = s * R;
		N = vec4( 1.0 / s, 1.0, 0.0, 0.0 );
	} else {
		mat3 K = mat3( 0.0 );
		for ( int k = 0; k < GCS_TABLE_SLOTS; k ++ ) {${TABLE_SLOT}
			K += w * gcsPartScale( id, row );
		}
		M = R * K;
		N = gcsNormalTexel( K );
	}
	if ( centre.w > 0.5 ) {
		// With a centre: turn about it, the centre moved by LBS (M p + T = Σ w_i S_i p).
		vec3 moved = vec3( 0.0 ); // Σ w_i (S_i p − p): where LBS moves the centre p
		for ( int k = 0; k < GCS_TABLE_SLOTS; k ++ ) {${TABLE_SLOT}
			mat3 S; vec3 t; vec4 q;
			gcsJoint( base, int( id ), S, t, q );
			moved += w * ( S * centre.xyz + t - centre.xyz );
		}
		T = moved - ( M * centre.xyz - centre.xyz );
	}
}
`;

/**
 * What both passes (node and DQS joint) declare: the counts that map a fragment to its node (or
 * joint) and instance, and the four float targets (GPU_NODE_TEXTURES) they write.
 */
const PASS_HEAD = /* glsl */ `
uniform int gcsNodeCount;
uniform int gcsSectionCount;
uniform int gcsJointStride;
uniform int gcsTargetWidth;
uniform int gcsFirstRow;
layout( location = 0 ) out highp vec4 gcsRow0;
layout( location = 1 ) out highp vec4 gcsRow1;
layout( location = 2 ) out highp vec4 gcsRow2;
layout( location = 3 ) out highp vec4 gcsNormal;
`;

/**
 * The node pass's fragment shader: one fragment per node (instance k's node s is node k·sections +
 * s), four outputs (GPU_NODE_TEXTURES): the rows of [M | T] and the normal texel.
 */
const NODE_PASS_FRAGMENT = /* glsl */ `${PASS_HEAD}uniform highp sampler2D gcsTable;
${NODE_MATHS}${JOINT_POSE}${NODE_FROM_PARTS}
// Section s: its joints, weights and centre of rotation from the static table (GCS_TABLE_TEXELS per
// section: per 4 slots a texel of joints, −1 past the last, then one of weights; last, the centre).
void gcsSectionBlend( const in int base, const in int row, const in int s, out mat3 M, out vec3 T, out vec4 N ) {
	int at = GCS_TABLE_TEXELS * s;
	vec4 joints1 = vec4( - 1.0 ), weights1 = vec4( 0.0 );
	#if GCS_TABLE_SLOTS > 4
	joints1 = gcsTexel( gcsTable, at + 2 ); weights1 = gcsTexel( gcsTable, at + 3 );
	#endif
	gcsBlend( base, row, gcsTexel( gcsTable, at ), gcsTexel( gcsTable, at + 1 ), joints1, weights1, gcsTexel( gcsTable, at + GCS_TABLE_TEXELS - 1 ), M, T, N );
}
#ifdef GCS_PLACED
uniform highp sampler2D gcsPlacements;
// A crowd's instance placement P folded into its nodes (the vertex stage then places nothing):
// x ↦ P·(M x + T), and the normal texel's scale y / ∛det(P)² so that N = cof(P·M·x)·y turns a
// normal by P's rotation where P scales uniformly (by P⁻ᵀ, up to length, where it does not).
void gcsPlace( const in int instance, inout mat3 M, inout vec3 T, inout vec4 N ) {
	int i = 4 * instance;
	mat4 P = mat4( gcsTexel( gcsPlacements, i ), gcsTexel( gcsPlacements, i + 1 ), gcsTexel( gcsPlacements, i + 2 ), gcsTexel( gcsPlacements, i + 3 ) );
	mat3 P3 = mat3( P );
	M = P3 * M;
	T = P3 * T + P[ 3 ].xyz;
	float d = determinant( P3 );
	if ( d != 0.0 ) N.y /= sign( d ) * pow( abs( d ), 2.0 / 3.0 );
}
#endif
void main() {
	int node = ( int( gl_FragCoord.y ) - gcsFirstRow ) * gcsTargetWidth + int( gl_FragCoord.x );
	if ( node >= gcsNodeCount ) { gcsRow0 = gcsRow1 = gcsRow2 = gcsNormal = vec4( 0.0 ); return; }
	int instance = node / gcsSectionCount;
	mat3 M; vec3 T; vec4 N;
	gcsSectionBlend( instance * gcsJointStride, gcsJointRow + instance, node - instance * gcsSectionCount, M, T, N );
	#ifdef GCS_PLACED
	gcsPlace( instance, M, T, N );
	#endif
	gcsNormal = N;
	gcsRow0 = vec4( M[ 0 ][ 0 ], M[ 1 ][ 0 ], M[ 2 ][ 0 ], T.x );
	gcsRow1 = vec4( M[ 0 ][ 1 ], M[ 1 ][ 1 ], M[ 2 ][ 1 ], T.y );
	gcsRow2 = vec4( M[ 0 ][ 2 ], M[ 1 ][ 2 ], M[ 2 ][ 2 ], T.z );
}
`;

/**
 * DQS's joint pass (WebGLRenderer): two fragments per joint of every instance (instance k's joint j
 * has texels (2j, k) and (2j + 1, k): one row per instance, DQS_TEXELS_PER_JOINT): first the
 * joint's rotation quaternion q, its dual part ½ (0, t)·q and its uniform scale u (0 where K is not
 * one), then the rows of its scale part K = Rᵀ S — what each vertex's dual-quaternion blend needs
 * per joint, computed once per joint and frame instead of once per vertex and influence.
 */
const DQS_PASS_FRAGMENT = /* glsl */ `${PASS_HEAD}${NODE_MATHS}${JOINT_POSE}
// s where k is a positive uniform scale s·I within ${RIGID_JOINT_TOLERANCE} × s (the CPU's test for a
// uniform frame, per joint; s exactly the diagonal where its entries are equal), else 0.
float gcsRigidScale( const in mat3 k ) {
	float s = ( k[ 0 ][ 0 ] + k[ 1 ][ 1 ] + k[ 2 ][ 2 ] ) / 3.0;
	vec3 e = max( max( abs( k[ 0 ] - vec3( s, 0.0, 0.0 ) ), abs( k[ 1 ] - vec3( 0.0, s, 0.0 ) ) ), abs( k[ 2 ] - vec3( 0.0, 0.0, s ) ) );
	if ( ! ( s > 0.0 && max( max( e.x, e.y ), e.z ) <= ${f(RIGID_JOINT_TOLERANCE)} * s ) ) return 0.0;
	return k[ 0 ][ 0 ] == k[ 1 ][ 1 ] && k[ 1 ][ 1 ] == k[ 2 ][ 2 ] ? k[ 0 ][ 0 ] : s;
}
void main() {
	int x = int( gl_FragCoord.x ), joint = x / ${DQS_TEXELS_PER_JOINT};
	mat3 S; vec3 t; vec4 q;
	gcsJoint( ( int( gl_FragCoord.y ) - gcsFirstRow ) * gcsJointStride, joint, S, t, q );
	mat3 K = transpose( gcsRotation( q, 2.0 ) ) * S;
	gcsNormal = vec4( 0.0 );
	if ( x == joint * ${DQS_TEXELS_PER_JOINT} ) {
		gcsRow0 = q;
		gcsRow1 = 0.5 * vec4( q.w * t + cross( t, q.xyz ), - dot( t, q.xyz ) );
		gcsRow2 = vec4( gcsRigidScale( K ), 0.0, 0.0, 0.0 );
	} else {
		gcsRow0 = vec4( K[ 0 ][ 0 ], K[ 1 ][ 0 ], K[ 2 ][ 0 ], 0.0 );
		gcsRow1 = vec4( K[ 0 ][ 1 ], K[ 1 ][ 1 ], K[ 2 ][ 1 ], 0.0 );
		gcsRow2 = vec4( K[ 0 ][ 2 ], K[ 1 ][ 2 ], K[ 2 ][ 2 ], 0.0 );
	}
}
`;

/** Two triangles over the pass's texels in its page (gcsRect: their corners in clip space): one fragment per texel. */
const NODE_PASS_VERTEX = /* glsl */ `
uniform vec4 gcsRect;
void main() {
	int i = gl_VertexID % 3 + gl_VertexID / 3; // 0 1 2, 1 2 3: the corners (0, 0), (1, 0), (0, 1), (1, 1)
	vec2 corner = vec2( float( i & 1 ), float( i >> 1 ) );
	gl_Position = vec4( mix( gcsRect.xy, gcsRect.zw, corner ), 0.0, 1.0 );
}
`;

const tableDefines = (slots: TableSlots): string => `#define GCS_TABLE_SLOTS ${slots}\n#define GCS_TABLE_TEXELS ${tableTexelsPerSection(slots)}\n`;

/** Slots of the section table: 4 or 8 joints per section. */
function checkSlots(slots: unknown, fn: string): void {
  if (slots !== 4 && slots !== 8) throw new GcsError('INVALID_ARGUMENT', `${fn}: the section table has 4 or 8 joints per section; got ${asGiven(slots)}`);
}

/**
 * The variant of a patched shader: path 'joints' | 'sections', method 'gcs' | 'lbs' | 'dqs', slots 4 | 8.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
 */
export function checkVariant(path: unknown, method: unknown, slots: unknown, fn: string): void {
  if (path !== 'joints' && path !== 'sections') throw new GcsError('INVALID_ARGUMENT', `${fn}: the GPU path must be 'joints' or 'sections'; got ${asGiven(path)}`);
  if (method !== 'gcs' && method !== 'lbs' && method !== 'dqs') throw new GcsError('INVALID_ARGUMENT', `${fn}: the GPU backend runs 'gcs', 'lbs' or 'dqs'; got ${asGiven(method)}`);
  checkSlots(slots, fn);
}

/**
 * The node pass's shaders (GLSL 3: four outputs) for a section table of `slots` joints per section (GpuSections.tableSlots);
 * `placed`: each instance's placement (texture gcsPlacements, four texels per instance) folded into its nodes.
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
 */
export function nodePassShaders(slots: TableSlots, placed = false): {
  /** GLSL 3 vertex shader: one triangle covering the target. */
  vertexShader: string;
  /** GLSL 3 fragment shader: one fragment per node, writing the rows of [M | T] and the normal texel to the four node textures. */
  fragmentShader: string;
} {
  checkSlots(slots, 'nodePassShaders');
  return { vertexShader: NODE_PASS_VERTEX, fragmentShader: `${placed ? `${PLACED}\n` : ''}${tableDefines(slots)}${NODE_PASS_FRAGMENT}` };
}

/**
 * The define that folds a crowd's instance placement into the node pass (gcsPlace) and, in the
 * vertex stage, makes three.js's instancing chunks place nothing: the placement is in the nodes.
 */
const PLACED = '#define GCS_PLACED';

/** A patched vertex shader of a crowd whose node pass places its instances: three.js's `instanceMatrix` is the identity there. */
export function placedInNodes(vertexShader: string): string {
  return `${PLACED}\n#ifdef USE_INSTANCING\n#define instanceMatrix mat4( 1.0 )\n#endif\n${vertexShader}`;
}

/** DQS's joint pass shaders (GLSL 3: four outputs): two fragments per joint, its quaternion, dual part and uniform scale, then its scale part K (internal: not an entry's export). */
export function dqsPassShaders(slots: TableSlots): { vertexShader: string; fragmentShader: string } {
  return { vertexShader: NODE_PASS_VERTEX, fragmentShader: `${tableDefines(slots)}${DQS_PASS_FRAGMENT}` };
}

/** The vertex stage's declarations: the node textures (written by the node pass) and how normals turn. */
const NODE_PARS = /* glsl */ `
${Array.from({ length: GPU_NODE_TEXTURES }, (_, t) => `uniform highp sampler2D gcsNodes${t};`).join('\n')}${COMMON_PARS}
// Node s of this instance: x ↦ M x + T, its normal matrix N (from gcsNormalTexel's texel)
// and whether normals renormalise.
void gcsNode( const in int s, out mat3 M, out vec3 T, out mat3 N, out bool renorm ) {
	int i = gcsBase + s;
	#ifdef USE_INSTANCING
	i += gl_InstanceID * gcsStride;
	#endif
	int w = textureSize( gcsNodes0, 0 ).x, y = i / w;
	ivec2 at = ivec2( i - y * w, y );
	vec4 r0 = texelFetch( gcsNodes0, at, 0 ), r1 = texelFetch( gcsNodes1, at, 0 ), r2 = texelFetch( gcsNodes2, at, 0 ), n = texelFetch( gcsNodes3, at, 0 );
	M = transpose( mat3( r0.xyz, r1.xyz, r2.xyz ) );
	T = vec3( r0.w, r1.w, r2.w );
	renorm = n.w < 0.0;
	mat3 a = M * n.x;
	N = mat3( cross( a[ 1 ], a[ 2 ] ), cross( a[ 2 ], a[ 0 ] ), cross( a[ 0 ], a[ 1 ] ) ) * n.y;
}
${TURN_JOINT}`;

/** Per vertex, once: its (blended) node transform and normal matrix, read from the node texture. */
const JOINT_BASE = /* glsl */ `
	mat3 gcsM, gcsN;
	vec3 gcsT;
	bool gcsNear = false, gcsAlmostEqual = false, gcsNormalise;
	{
		#ifdef GCS_SMOOTH
		int sa = int( ${BLEND_ATTRIBUTE}.x + 0.5 ), sb = int( ${BLEND_ATTRIBUTE}.y + 0.5 );
		int sc = int( ${BLEND_THIRD_ATTRIBUTE}.x + 0.5 );
		gcsNode( sa, gcsM, gcsT, gcsN, gcsNormalise );
		if ( sb != sa ) {
			mat3 mb, nb; vec3 tb; bool rb;
			gcsNode( sb, mb, tb, nb, rb );
			float f = ${BLEND_ATTRIBUTE}.z;
			bool ra = gcsNormalise;
			float trace = dot( gcsN[ 0 ], nb[ 0 ] ) + dot( gcsN[ 1 ], nb[ 1 ] ) + dot( gcsN[ 2 ], nb[ 2 ] );
			mat3 ma = gcsM, na = gcsN; vec3 ta = gcsT;
			gcsM = ma + f * ( mb - ma );
			gcsT = ta + f * ( tb - ta );
			gcsN = na + f * ( nb - na );
			if ( sc != sa ) {
				// A three-joint lattice cell: + g·(C − A); the least pairwise trace decides the fix.
				mat3 mc, nc; vec3 tc; bool rc;
				gcsNode( sc, mc, tc, nc, rc );
				float g = ${BLEND_THIRD_ATTRIBUTE}.y;
				gcsM += g * ( mc - ma );
				gcsT += g * ( tc - ta );
				gcsN += g * ( nc - na );
				trace = min( trace, min( dot( na[ 0 ], nc[ 0 ] ) + dot( na[ 1 ], nc[ 1 ] ) + dot( na[ 2 ], nc[ 2 ] ),
					dot( nb[ 0 ], nc[ 0 ] ) + dot( nb[ 1 ], nc[ 1 ] ) + dot( nb[ 2 ], nc[ 2 ] ) ) );
				gcsNear = ! ra && ! rb && ! rc && trace > ${f(NEAR_TRACE3)};
				gcsAlmostEqual = gcsNear && trace > ${f(ALMOST_EQUAL_TRACE3)};
			} else {
				gcsNear = ! ra && ! rb && trace > ${f(NEAR_TRACE)};
				gcsAlmostEqual = gcsNear && trace > ${f(ALMOST_EQUAL_TRACE)};
			}
			gcsNormalise = true;
		}
		#else
		gcsNode( int( ${SECTION_ATTRIBUTE} + 0.5 ), gcsM, gcsT, gcsN, gcsNormalise );
		#endif
	}
`;

const JOINT_NORMAL = turned((v) => `gcsTurnJoint( ${v}, gcsN, gcsNear, gcsAlmostEqual, gcsNormalise )`);

const JOINT_POSITION = /* glsl */ `
	transformed = gcsM * transformed + gcsT;
`;

// ------------------------------------------------------------ LBS and DQS per vertex (backend 'gpu', method 'lbs' | 'dqs')
// Each vertex blends its own joints (≤ 4, or 8 with GCS_TABLE_SLOTS 8) at its own weights, read
// from attributes: the rig's weights as the core normalises them, joint −1 where the weight is 0.

/** Declarations: the joint poses (per frame) and the vertex's influences. */
const SKIN_PARS = /* glsl */ `
uniform int gcsBase;
uniform int gcsStride;
attribute vec4 ${INFLUENCE_ATTRIBUTES[0]};
attribute vec4 ${WEIGHT_ATTRIBUTES[0]};
#if GCS_TABLE_SLOTS > 4
attribute vec4 ${INFLUENCE_ATTRIBUTES[1]};
attribute vec4 ${WEIGHT_ATTRIBUTES[1]};
#endif
${NODE_MATHS}${TURN_JOINT}
int gcsFirstJoint() {
	int i = gcsBase;
	#ifdef USE_INSTANCING
	i += gl_InstanceID * gcsStride;
	#endif
	return i;
}
`;

/** The second set of influences, or none. */
const SECOND_SET = /* glsl */ `
		vec4 gcsJ1 = vec4( - 1.0 ), gcsW1 = vec4( 0.0 );
		#if GCS_TABLE_SLOTS > 4
		gcsJ1 = ${INFLUENCE_ATTRIBUTES[1]}; gcsW1 = ${WEIGHT_ATTRIBUTES[1]};
		#endif
`;

/** LBS (as three.js and the CPU's LBS): M = Σ w_j S_j; normals by M, then unit length. */
const LBS_BASE = /* glsl */ `
	mat3 gcsM;
	vec3 gcsT;
	vec4 gcsRest = vec4( 0.0, 0.0, 0.0, 1.0 );
	{${SECOND_SET}
		int base = gcsFirstJoint();
		vec4 r0 = vec4( 0.0 ), r1 = vec4( 0.0 ), r2 = vec4( 0.0 );
		for ( int k = 0; k < GCS_TABLE_SLOTS; k ++ ) {
			#if GCS_TABLE_SLOTS > 4
			float id = k < 4 ? ${INFLUENCE_ATTRIBUTES[0]}[ k ] : gcsJ1[ k - 4 ], w = k < 4 ? ${WEIGHT_ATTRIBUTES[0]}[ k ] : gcsW1[ k - 4 ];
			#else
			float id = ${INFLUENCE_ATTRIBUTES[0]}[ k ], w = ${WEIGHT_ATTRIBUTES[0]}[ k ];
			#endif
			if ( ! ( w > 0.0 ) ) continue;
			vec4 a0, a1, a2, q;
			gcsJointTexels( base, int( id ), a0, a1, a2, q );
			r0 += w * a0; r1 += w * a1; r2 += w * a2;
			if ( k == 0 ) gcsRest = q; // where the blend collapses (bones scaled to 0): the first influence's rotation
		}
		gcsM = transpose( mat3( r0.xyz, r1.xyz, r2.xyz ) );
		gcsT = vec3( r0.w, r1.w, r2.w );
	}
`;

const LBS_NORMAL = turned((v) => `gcsTurnLbs( ${v}, gcsM, gcsRest )`);

const LBS_TURN = /* glsl */ `
vec3 gcsTurnLbs( const in vec3 v, const in mat3 M, const in vec4 q ) {
	vec3 n = M * v;
	float len2 = dot( n, n );
	if ( len2 > 1e-24 && len2 < 1e24 ) return n * ( 1.0 / sqrt( len2 ) );
	n = gcsRotation( q, 2.0 ) * v;
	float l = length( n );
	return l > 0.0 ? n / l : v;
}
`;

/**
 * DQS (the CPU's dqsVertices) from the joint pass's textures: per influence the joint's quaternion,
 * dual part and uniform scale as the pass wrote them; the blend, then M = s·R and the normal by R
 * where every joint of the vertex is a uniform scale (the CPU's quaternion-only path: no scale
 * parts read), else the scale parts K_j blended, M = R·K and the normal texel's matrix — the
 * arithmetic of gcsBlend without a centre, step for step.
 */
const DQS_PARS = /* glsl */ `
${Array.from({ length: GPU_NODE_TEXTURES }, (_, t) => `uniform highp sampler2D gcsNodes${t};`).join('\n')}
attribute vec4 ${INFLUENCE_ATTRIBUTES[0]};
attribute vec4 ${WEIGHT_ATTRIBUTES[0]};
#if GCS_TABLE_SLOTS > 4
attribute vec4 ${INFLUENCE_ATTRIBUTES[1]};
attribute vec4 ${WEIGHT_ATTRIBUTES[1]};
#endif
uniform int gcsFirstRow;
${ROTATION}${TURN_JOINT}
// Joint j's first texel in the joint pass's targets (one row per instance from gcsFirstRow: no division per joint).
ivec2 gcsDqsAt( const in float j ) {
	#ifdef USE_INSTANCING
	return ivec2( int( j ) * ${DQS_TEXELS_PER_JOINT}, gcsFirstRow + gl_InstanceID );
	#else
	return ivec2( int( j ) * ${DQS_TEXELS_PER_JOINT}, gcsFirstRow );
	#endif
}
// Joint j's scale part K (columns), from its second texel.
mat3 gcsDqsScale( const in float j ) {
	ivec2 at = gcsDqsAt( j ) + ivec2( 1, 0 );
	return transpose( mat3( texelFetch( gcsNodes0, at, 0 ).xyz, texelFetch( gcsNodes1, at, 0 ).xyz, texelFetch( gcsNodes2, at, 0 ).xyz ) );
}
// The normal matrix of M = R·K (R the blend's rotation) as gcsNormalTexel decides it, built
// directly: R where K is a positive uniform scale (1e-4; the CPU's s·R, normalised), else
// R·cof(K/kbig)/big with normals renormalised; 0 where K has collapsed (the rest direction kept).
void gcsDqsNormal( const in mat3 R, const in mat3 k, out mat3 N, out bool renorm ) {
	float s = ( k[ 0 ][ 0 ] + k[ 1 ][ 1 ] + k[ 2 ][ 2 ] ) / 3.0;
	vec3 e = max( max( abs( k[ 0 ] - vec3( s, 0.0, 0.0 ) ), abs( k[ 1 ] - vec3( 0.0, s, 0.0 ) ) ), abs( k[ 2 ] - vec3( 0.0, 0.0, s ) ) );
	renorm = ! ( s > 0.0 && max( max( e.x, e.y ), e.z ) <= ${f(UNIFORM_SCALE_TOLERANCE)} * s );
	if ( ! renorm ) { N = R; return; }
	vec3 m = max( max( abs( k[ 0 ] ), abs( k[ 1 ] ) ), abs( k[ 2 ] ) );
	float kbig = max( max( m.x, m.y ), m.z );
	mat3 a = k * ( kbig > ${f(COLLAPSED)} ? 1.0 / kbig : 0.0 );
	mat3 c = mat3( cross( a[ 1 ], a[ 2 ] ), cross( a[ 2 ], a[ 0 ] ), cross( a[ 0 ], a[ 1 ] ) );
	m = max( max( abs( c[ 0 ] ), abs( c[ 1 ] ) ), abs( c[ 2 ] ) );
	float big = max( max( m.x, m.y ), m.z );
	N = R * ( c * ( big > ${f(COLLAPSED)} ? 1.0 / big : 0.0 ) );
}
`;

/** Influence k of the vertex: its joint id and weight (the second set past 4). */
const INFLUENCE = /* glsl */ `
			#if GCS_TABLE_SLOTS > 4
			float id = k < 4 ? ${INFLUENCE_ATTRIBUTES[0]}[ k ] : gcsJ1[ k - 4 ], w = k < 4 ? ${WEIGHT_ATTRIBUTES[0]}[ k ] : gcsW1[ k - 4 ];
			#else
			float id = ${INFLUENCE_ATTRIBUTES[0]}[ k ], w = ${WEIGHT_ATTRIBUTES[0]}[ k ];
			#endif
			if ( ! ( w > 0.0 ) ) continue;`;

const DQS_BASE = /* glsl */ `
	mat3 gcsM, gcsN;
	vec3 gcsT;
	bool gcsNormalise = false;
	{${SECOND_SET}
		vec4 pivot = texelFetch( gcsNodes0, gcsDqsAt( ${INFLUENCE_ATTRIBUTES[0]}.x ), 0 );
		vec4 br = vec4( 0.0 ), bd = vec4( 0.0 );
		float s = 0.0;
		bool rigid = true; // every joint's K is a uniform scale: the blend of scales is s·I
		for ( int k = 0; k < GCS_TABLE_SLOTS; k ++ ) {${INFLUENCE}
			ivec2 at = gcsDqsAt( id );
			vec4 q = texelFetch( gcsNodes0, at, 0 );
			float sw = dot( q, pivot ) < 0.0 ? - w : w;
			br += sw * q;
			bd += sw * texelFetch( gcsNodes1, at, 0 );
			float u = texelFetch( gcsNodes2, at, 0 ).x;
			s += w * u;
			rigid = rigid && u > 0.0;
		}
		float inv2 = 1.0 / dot( br, br );
		gcsT = ( 2.0 * inv2 ) * ( br.w * bd.xyz - bd.w * br.xyz - cross( bd.xyz, br.xyz ) );
		mat3 R = gcsRotation( br, 2.0 * inv2 );
		if ( rigid ) {
			gcsM = s * R;
			gcsN = R;
		} else {
			mat3 K = mat3( 0.0 );
			for ( int k = 0; k < GCS_TABLE_SLOTS; k ++ ) {${INFLUENCE}
				K += w * gcsDqsScale( id );
			}
			gcsM = R * K;
			gcsDqsNormal( R, K, gcsN, gcsNormalise );
		}
	}
`;

const DQS_NORMAL = turned((v) => `gcsTurnJoint( ${v}, gcsN, false, false, gcsNormalise )`);

const HOOKS = ['#include <skinning_pars_vertex>', '#include <skinbase_vertex>', '#include <skinning_vertex>'] as const;

/**
 * The vertex shader of a three.js built-in material (or any shader written with its chunks) with
 * three's skinning chunks replaced by GCS's: path 'sections', the section transforms come from the
 * `gcsSections` texture; path 'joints', each vertex reads its nodes' transforms from the `gcsNodes`
 * texture the node pass wrote (node-pass.ts) and blends them. Morph targets still apply first
 * (three's order), then the transform; normals and tangents turn with the normal matrix. Where a
 * material compiles `skinbase_vertex` out (MeshBasicMaterial keeps it under
 * `USE_ENVMAP || USE_SKINNING`), the transform is read in `skinning_vertex` instead. Throws GcsError
 * 'INVALID_ARGUMENT' when the shader lacks the chunks (a ShaderMaterial written without them).
 * @throws GcsError `INVALID_ARGUMENT` when an argument is not of its kind (a material that is not a three.js material, uniforms or sections that are not objects, an unknown path, method or slot count).
 */
export function patchVertexShader(source: string, smooth: boolean, path: GpuPath = 'sections', method: GpuMethod = 'gcs', slots: TableSlots = 4): string {
  checkString(source, 'source', 'patchVertexShader');
  checkVariant(path, method, slots, 'patchVertexShader');
  for (const hook of HOOKS)
    if (!source.includes(hook)) throw new GcsError('INVALID_ARGUMENT', `this vertex shader has no '${hook}': gcs-skin/gpu patches three.js's skinning chunks`);
  if (path !== 'joints' && path !== 'sections') throw new GcsError('INVALID_ARGUMENT', `the GPU path must be 'joints' or 'sections'; got '${String(path)}'`);
  if (method !== 'gcs' && method !== 'lbs' && method !== 'dqs') throw new GcsError('INVALID_ARGUMENT', `the GPU backend runs 'gcs', 'lbs' or 'dqs'; got '${String(method)}'`);
  const joints = path === 'joints';
  const [pars, base, position, normal] = method === 'lbs' ? [`${SKIN_PARS}${LBS_TURN}`, LBS_BASE, JOINT_POSITION, LBS_NORMAL]
    : method === 'dqs' ? [DQS_PARS, DQS_BASE, JOINT_POSITION, DQS_NORMAL]
    : joints ? [NODE_PARS, JOINT_BASE, JOINT_POSITION, JOINT_NORMAL] : [PARS, BASE, POSITION, NORMAL];
  let out = source
    .replace(HOOKS[0], `${HOOKS[0]}\n${pars}`)
    .replace(HOOKS[1], `#define GCS_BASE\n${base}`)
    .replace(HOOKS[2], `#ifndef GCS_BASE\n${base}\n#endif\n${position}`);
  // Materials that do not compute normals (depth, distance) have no skinnormal chunk.
  out = out.replace('#include <skinnormal_vertex>', normal);
  const defines = method === 'gcs' ? '' : tableDefines(slots);
  return `${smooth && method === 'gcs' ? '#define GCS_SMOOTH\n' : ''}${defines}${out}`;
}
