// Advection: the first-order flow x' = u(x, t) that a velocity-prescribing field imposes.
#pragma once

#include <string_view>

#include "fields/ForceSet.h"
#include "integrators/AdvectionScheme.h"
#include "integrators/StagePasses.h"

namespace tickfx {

struct StepTime;

/// Advances a pool along x' = u(x, t) by one tick. After the step the velocity column holds the
/// mean velocity the step moved each particle with (Euler: u(x, t); midpoint: the midpoint
/// sample; Heun and RK4: their weighted means), so a cache shows the velocity that carried it,
/// and previousPosition() the position before the step. Keeps scratch columns between calls:
/// one instance serves one pool.
///
/// Visiting order: each particle's step is a pure function of its own row, so the order in which
/// rows are visited changes no bit. With Visits::LeafOrder (the default) a block of rows whose
/// positions are scattered over a grid field's leaves is visited leaf by leaf
/// (integrators/LeafOrder.h): the positions of a tile of rows in that order are gathered, every
/// stage runs on the tile, and the results are scattered back to the same rows; the pool's rows
/// and their order stay as they are. Only where the forces allow it (every module local and
/// reading nothing but positions: ForceSet::gathersVelocity, and one of them has grid blocks);
/// elsewhere, and with Visits::RowOrder (the reference the tests pin it to), rows are visited in
/// order.
class Advection {
 public:
  enum class Visits { RowOrder, LeafOrder };
  explicit Advection(AdvectionScheme scheme, Visits visits = Visits::LeafOrder)
      : scheme_(scheme), visits_(visits) {}
  AdvectionScheme scheme() const { return scheme_; }
  Visits visits() const { return visits_; }
  /// Advances `rows` (see StepRows). `afterEachTile`: as runPasses() takes it (in leaf order, on
  /// tiles of consecutive rows once their block is done).
  void step(ParticlePool& pool, const ForceSet& forces, const StepTime& time, const StepRows& rows,
            const RowPass& afterEachTile = {});

 private:
  struct Step;  // one step's constants and per-tile work (Advection.cpp)
  void stepRowOrder(const Step& s, const StepRows& rows, bool fused, const RowPass& afterEachTile);
  void stepLeafOrder(const Step& s, const StepRows& rows, const RowPass& afterEachTile);

  AdvectionScheme scheme_;
  Visits visits_;
  StageScratch scratch_{7};  // k1..k4, then the stage positions x2 x3 x4
};

}  // namespace tickfx
