// The classic model's build, raw → runtime (as ozz-animation's offline builders): a Rig in, a
// ClassicModel out, one function per step. The rig's analysis (steps 1–3: parts, their triangles,
// chains, trunk splits, contour frames, welded edges) does not depend on which parts the on-skin
// test carries, so a rebuild without them starts at step 4 from a copy of the analysed parts.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>
#include <glm/glm.hpp>
#include "classic_model.h"
#include "classic_rays.h"
#include "rig.h"

namespace gcs {

class ClassicBuild {
 public:
  // Steps 1–3. Settings must be in range (buildClassic checks them). May throw std::bad_alloc.
  ClassicBuild(const Rig& rig, uint32_t contours, uint32_t rays, float bulge);

  // Steps 4–9. Parts flagged in `carry` (if given) are carried (GCS_CLASSIC_OFF_SURFACE). The
  // model is the caller's. May throw std::bad_alloc.
  ClassicModel* build(const std::vector<uint8_t>* carry);

  // Per ring vertex of the last build: the rig triangle its ray hit (the triangle count: a filled miss).
  const std::vector<uint32_t>& ringTriangles() const { return ringTriangle; }

 private:
  // A triangle edge between welded vertices lo < hi; `from` is where triangle `tri` walks it from.
  struct WeldedEdge {
    uint32_t lo, hi, from, tri;
  };
  // A boundary loop between tubes and carried skin: welded vertices in order, the part whose end it
  // closes, and which end.
  struct Loop {
    std::vector<uint32_t> groups;
    uint32_t part = 0;
    bool distal = false;
  };
  // Per loop: its band (classic_bands.cpp). The band's own vertices are skin points under the band
  // carried by DQS like the carried skin, after the carried copies: [bandFirst, bandFirst + count).
  struct BandPlan {
    std::vector<uint32_t> loop;        // the loop's welded vertices in the ring's turn, from the one nearest ray 0
    std::vector<float> beta;           // their unwrapped angles about the end ring (n + 1: back to the first)
    std::vector<uint32_t> triangles;   // kRingRef | ring index, kLoopRef | loop index, or a band vertex; empty: one zip
  };
  struct BandVertex {
    glm::vec3 position, normal;
    glm::uvec4 joints[2];              // slots 0..3, 4..7
    glm::vec4 weights[2];
  };

  // --- Steps 1–3: the rig's analysis (kept across rebuilds).
  void findParts();          // 1. parts by dominant weight (welded), their parents and children
  void gatherOwnTriangles(); // 2. each part's triangles (with a vertex in it)
  void findChains();         // 3. directions, chain parts long enough to be tubes
  void splitTrunk();         //    branching trunk parts resampled along the trunk
  void transportFrames();    //    contour reference directions carried down each chain
  void countContours();      //    contours per part by bone length
  void sortWeldedEdges();    //    triangle edges by welded vertex (for boundary loops)
  void findPieces();         //    connected pieces of skin (a rig of separate shells has several)

  // --- Steps 4–9: one model.
  void newModel();
  void decideParts();        // 4. rays, bends, trunk cuts, boundary loops: resampled or carried
  void settleRayTests();
  bool recutTrunk(int round);
  void computeOwners();
  void traceLoops(std::vector<uint8_t>& failed);
  bool carrySeams(const std::vector<uint8_t>& failed);
  bool endTubesAtLoops();
  float fullRingEnd(uint32_t j, float end, float other);
  void castFinalContours();  //    the contours of the parts that stay resampled
  void layContours();        // 5. rings, chains root → leaf, shared joint rings
  void fillEmptyContours();  //    misses filled, empty contours from their neighbours
  void contourInfluences();  //    the skin each contour resamples, as influences
  void addCaps();            //    flat fans on closed ends that meet nothing
  void planBands();          //    band rows of new skin vertices between each end ring and its loop
  bool planBand(const Loop& loop, BandPlan& plan);
  struct BandChart;          //    planBand's steps (classic_bands.cpp):
  void orderLoop(const Loop& loop, BandChart& chart, BandPlan& plan) const;  // the loop in the ring's turn
  bool chartLoop(BandChart& chart, const BandPlan& plan) const;              // its heights above the ring
  void raiseColumns(const Loop& loop, BandChart& chart);                     // columns of band vertices
  bool layStrips(BandChart& chart, BandPlan& plan);                          // strips between them, clipped
  BandVertex skinPoint(const glm::vec3& x, const glm::vec3* corner, const uint32_t* v, uint32_t fallbackJoint,
                       const glm::vec3& fallbackNormal) const;
  void copyCarriedVertices();// 6. carried input vertices, grouped by part
  void buildTriangles();     // 7. tube quads, bands, caps, carried triangles
  void zipBand(const Loop& loop, const BandPlan& plan);
  void writeReport();        // 8. report, contour and source per vertex, detail-loss inputs
  void restPose();           // 9. the bind pose as the initial output

  // Helpers over the shared state.
  float tOn(const ClassicPart& P, uint32_t v) const;
  bool member(uint32_t j, uint32_t x) const;
  bool beforeCut(const ClassicPart& P, uint32_t v) const;
  int32_t baseOwner(uint32_t g) const;
  bool updateCut(uint32_t j);
  void updateExtents();
  struct PartTriangles;
  PartTriangles& trianglesOf(uint32_t j);
  void endNormals(const ClassicPart& P, glm::vec3& nProx, glm::vec3& nDist) const;
  void contourFrame(const ClassicPart& P, float t, const glm::vec3& nProx, const glm::vec3& nDist, glm::vec3& centre,
                    glm::vec3& n, glm::vec3& u) const;
  void castPart(uint32_t j, uint32_t count, const glm::vec3& nProx, const glm::vec3& nDist, std::vector<float>& out,
                std::vector<uint32_t>& outTriangles, uint32_t& hitCount, uint32_t& inRangeHits, uint32_t& inRangeRays);
  bool shares(const ClassicPart& P) const;
  bool joinedBySkin(uint32_t a, uint32_t b) const;
  void carry(uint32_t j, uint8_t reason);
  uint32_t find(uint32_t x);
  void unite(uint32_t a, uint32_t b);
  ClassicPart& part(uint32_t j) { return model->parts[j]; }
  int32_t owner(uint32_t g) const { return gOwner[g]; }

  // Settings and the rig.
  const Rig& rig;
  const uint32_t contourSetting, k;
  const float bulge;
  const uint32_t J, T;  // joints, triangles

  // The analysis (steps 1–3).
  std::vector<uint32_t> representative, group;  // welded vertices: one rig vertex each; per rig vertex its welded vertex
  uint32_t G = 0;                               // welded vertex count
  std::vector<uint32_t> partOf;                 // per rig vertex: its part (dominant joint of its welded vertex)
  std::vector<uint32_t> gPart;                  // per welded vertex: its part
  std::vector<std::vector<uint32_t>> childParts;
  std::vector<uint32_t> triFirst, triList;      // each part's triangles: triList[triFirst[j] … triFirst[j + 1])
  // For a split trunk part j: per part x, the child of j whose subtree holds x (−1: none, or the continuing child's).
  std::vector<std::vector<int32_t>> branchOf;
  std::vector<WeldedEdge> edges;                // sorted by (lo, hi)
  std::vector<uint32_t> triPiece, piece;        // per triangle and welded vertex: its connected piece of skin
  std::vector<uint32_t> piecesFirst, pieceList;  // each part's pieces, sorted
  std::vector<ClassicPart> analysedParts;       // the parts as step 3 leaves them
  // Per part: the triangles its contours are cast against (castPart), kept across rebuilds.
  struct PartTriangles {
    bool valid = false;
    std::vector<uint32_t> parts;                // whose triangles
    std::vector<glm::vec3> corners;             // 3 per triangle, contiguous
    std::vector<uint32_t> triangle;             // the rig triangle of each
    classic::TriangleSlabs slabs;               // along the part's bone
    struct Cast {                               // contours cast from them, and what they hit
      uint32_t count;
      float tLo, tHi;
      glm::vec3 nProx, nDist;
      std::vector<float> radii;
      std::vector<uint32_t> triangles;
      uint32_t hitCount, inRangeHits, inRangeRays;
    };
    std::vector<Cast> casts;
  };
  std::vector<PartTriangles> partTriangles;

  // One model (steps 4–9).
  std::unique_ptr<ClassicModel> model;
  std::vector<std::vector<float>> hits;          // per part: contours × k radii
  std::vector<std::vector<uint32_t>> hitTriangles;
  std::vector<uint8_t> dirty;                    // parts whose ray test must run again
  std::vector<float> scratch, probe;
  std::vector<uint32_t> probeTriangles;
  std::vector<uint32_t> gathered, cut;           // castPart's parts, and the triangles a contour may cut
  std::vector<Loop> loops;
  std::vector<BandPlan> plans;
  std::vector<BandVertex> bandVertices;
  uint32_t bandFirst = 0;
  // Bands laid by earlier builds (the rebuild after the on-skin test meets the same loops and end
  // rings on every part it does not carry): the plan, its band vertices from 0, what it was laid from.
  struct LaidBand {
    uint32_t part;
    bool distal;
    std::vector<uint32_t> groups, gathered;
    glm::vec3 centre, normal, u;
    std::vector<float> radii;
    BandPlan plan;
    std::vector<BandVertex> vertices;
  };
  std::vector<LaidBand> laidBands;
  std::vector<uint8_t> triCarried;               // per rig triangle: it has a carried vertex
  std::vector<int32_t> gOwner;                   // per welded vertex: the part whose tube replaces it, or −1
  std::vector<uint32_t> root;                    // union-find over welded vertices
  std::vector<uint32_t> ringTriangle;
  std::vector<int64_t> outputOf, groupOutput;    // carried output vertex per rig / welded vertex, or −1
  uint32_t vertex = 0;                           // output vertices laid out so far
};

}  // namespace gcs
