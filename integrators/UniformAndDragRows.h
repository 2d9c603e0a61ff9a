// Under uniform forces and at most one linear drag (ForceSet::uniformAndDrag, the common effect:
// gravity, wind, air drag) a scheme's accelerations depend on nothing but each row's own velocity
// and the time, so it can form them in registers inside its update loop: one pass over the state
// a tick, where the general path writes each evaluation to a tile and reads it back. The
// accelerations come from ForceSet::evaluate()'s own operations, so the bits are those of the
// general path (test_passes compares them for every scheme).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <initializer_list>
#include <optional>
#include <tuple>

#include "fields/ForceSet.h"
#include "integrators/CheckedRows.h"
#include "integrators/Integrator.h"
#include "integrators/StagePasses.h"

namespace tickfx {

/// One component of the accelerations ForceSet::evaluate() gives a row under the UniformAndDrag
/// forms of a tick, by its operations: at stage s (StepTime::stage), the uniform sum at that time,
/// then + k·(air − v) with a drag (m/s²). kDrag is the forms' drag, fixed when the loop is
/// compiled so that the loop has no branch. The drag's k and air are the same at every stage and
/// held once: a loop that needs the acceleration at three times keeps five constants in
/// registers, not nine.
template <bool kDrag>
struct FormAccelerations {
  std::array<float, 3> uniform = {};  // m/s², at stages 0, 1, 2
  float k = 0.0f;                     // 1/s
  float air = 0.0f;                   // m/s

  /// The acceleration at `velocity` (m/s), of one row (float) or four (Lanes4).
  template <class Lane>
  Lane at(int stage, Lane velocity) const {
    const float u = uniform[static_cast<std::size_t>(stage)];
    if constexpr (kDrag) {
      return u + k * (air - velocity);
    } else {
      return broadcast<Lane>(u);
    }
  }
};

/// The forms of one tick's force evaluations, at StepTime::stage(0), (1) and (2) (t, t + dt/2,
/// t + dt), those a scheme asked for. Only the uniform part changes with the time (periodic
/// wind); the drag is the same at every stage.
struct TickForms {
  std::array<ForceSet::UniformAndDrag, 3> at;

  /// Whether every value of the forms is finite (a module's own form could be NaN; the
  /// exceptions check of the one pass needs finite constants as much as finite rows).
  bool finite() const {
    for (const ForceSet::UniformAndDrag& form : at) {
      if (!form.uniform.allFinite() || !form.air.allFinite() || !std::isfinite(form.k)) {
        return false;
      }
    }
    return true;
  }
};

/// The forms at the `stages` a scheme evaluates when the forces have that shape (which does not
/// depend on the time), else nullopt. Only those stages are asked for: a wind's sine is a
/// measurable part of a small tick.
inline std::optional<TickForms> tickForms(ParticlePool& pool, const ForceSet& forces,
                                          const StepTime& time, std::initializer_list<int> stages) {
  const Vec3View p = Vec3View::of(pool.position()), v = Vec3View::of(pool.velocity());
  TickForms forms;
  for (const int stage : stages) {
    const auto form = forces.uniformAndDrag({pool, p, v, time.stage(stage)});
    if (!form) return std::nullopt;
    forms.at[static_cast<std::size_t>(stage)] = *form;
  }
  return forms;
}

/// Component c's FormAccelerations; `body` gets them and returns what it returns (the drag chosen
/// once, outside any loop).
template <class Body>
auto withFormAccelerations(const TickForms& forms, int c, const Body& body) {
  const ForceSet::UniformAndDrag* any = &forms.at[0];
  for (const ForceSet::UniformAndDrag& form : forms.at) {
    if (form.drag) any = &form;
  }
  const auto make = [&](auto drag) {
    FormAccelerations<decltype(drag)::value> a;
    for (std::size_t s = 0; s < 3; ++s) a.uniform[s] = forms.at[s].uniform[c];
    a.k = any->k;
    a.air = any->air[c];
    return body(a);
  };
  return any->drag ? make(std::true_type{}) : make(std::false_type{});
}

/// A one-pass update of a tile: for each component c, `kernelFor(accelerations)` (a row kernel,
/// see updateRowsAs) over the columns `columnsOf(c)` gives, then, when some value may be
/// non-finite, the exact scan that flags the tile's rows. `copies`: see updateComponents().
template <class KernelFor, class ColumnsOf>
void updateTileUnderForms(NonfiniteCheck* check, ParticlePool& pool, RowRange rows,
                          const TickForms& forms, const KernelFor& kernelFor,
                          const ColumnsOf& columnsOf, bool copies, const SpanRows* span = nullptr) {
  updateComponents(
      check, pool, rows,
      [&](int c, Eigen::Index offset, Eigen::Index count, const auto& loop) {
        return withFormAccelerations(forms, c, [&](const auto& accelerations) {
          return loopAt(loop, kernelFor(accelerations), offset, count, columnsOf(c));
        });
      },
      copies, span);
}

/// The one pass of a scheme over every tile of `rows`: `beforeTile(tile)` first (the rows spawned
/// this tick start their history, say), then for each component the kernel
/// `kernelFor(accelerations)` gives, (at, pos, vel, last, extra...), over the position, the
/// velocity, the previous position and the `extra` columns of the tile. Checked (`check` set),
/// it sums what the kernels return, or, when the stepped rows start finite and the forms are
/// finite, runs the kernels unchecked and tests the exception flags after each tile: the sums are
/// one add per value, the flags one test a tile (their costs: docs/performance.md).
template <class KernelFor, class BeforeTile, class... Extra>
void runOnePass(ParticlePool& pool, StageScratch& scratch, const StepRows& rows,
                NonfiniteCheck* check, const TickForms& forms, const KernelFor& kernelFor,
                const BeforeTile& beforeTile, Extra&... extra) {
  Vec3Column& p = pool.position();
  Vec3Column& v = pool.velocity();
  // Fused tiles whose only other inputs are the forms: by exceptions when those are finite.
  const TileCheck tiles = tileCheck(check, pool, rows, forms.finite());
  const bool copies = writesPreviousRows(pool, rows);
  // A block's collisions need only the starts of the rows its span does not rule out.
  const bool spanned =
      rows.span.any() && rows.written != nullptr && copies && !writesPreviousColumn(pool, rows);
  runPasses(
      rows, true, scratch, {[&](const Tile& tile) {
        beforeTile(tile);
        const RowRange r = tile.rows();
        Vec3Rows pr = rowsOf(p, r), vr = rowsOf(v, r), old = previousRowsOf(pool, rows, r);
        std::array<Vec3Rows, sizeof...(Extra)> more{rowsOf(extra, r)...};
        SpanRows span;
        if (spanned) {
          const int a = rows.span.axis;
          span = {rows.span, old[a].data(), pr[a].data(), rows.written, r.begin - rows.writtenFrom};
        }
        updateTileUnderForms(
            tiles.sums, pool, r, forms, kernelFor,
            [&](int c) {
              return std::apply(
                  [&](auto&... e) {
                    return std::tuple(pr[c].data(), vr[c].data(), old[c].data(), e[c].data()...);
                  },
                  more);
            },
            copies, spanned ? &span : nullptr);
      }},
      tiles.afterEachTile);
}

/// runOnePass() of a scheme whose row update reads and writes the position, the velocity and
/// the previous position alone, with nothing to do before a tile.
template <class KernelFor>
void runStateUpdateUnderForms(ParticlePool& pool, StageScratch& scratch, const StepRows& rows,
                              NonfiniteCheck* check, const TickForms& forms,
                              const KernelFor& kernelFor) {
  runOnePass(pool, scratch, rows, check, forms, kernelFor, [](const Tile&) {});
}

}  // namespace tickfx
