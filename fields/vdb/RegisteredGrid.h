// New OpenVDB grids made by OpenVDB's grid registry rather than by GridT::create().
//
// Why: constructing a Grid<TreeT> (GridT::create(), a Tree's constructor, make_shared) emits its
// vtable in the calling translation unit, and with it every virtual member of Grid<TreeT> and
// Tree<TreeT>: topology and buffer I/O, statistics, pruning, TBB's parallel reductions. For the
// standard grid types libopenvdb already holds all of that, compiled once; made through the
// registry, a grid's class is instantiated here only for the members the caller itself uses
// (setValue, accessors), and its virtual members run from the library. Measured with g++ -O3:
// fields/vdb/LevelSetCollider.cpp compiled in 32.5 s with FloatGrid::create(), 19.2 s with this.
// The grid is the same class with the same tree, so what is written and sampled is unchanged.
#pragma once

#include <openvdb/openvdb.h>

#include <stdexcept>

namespace tickfx {

/// A new, empty grid of the registered type GridT (every standard OpenVDB grid type, points
/// included) with `background` as its background value. Shared ownership, as GridT::create().
/// Throws openvdb::LookupError (from the registry) if GridT is not registered.
template <typename GridT>
typename GridT::Ptr newRegisteredGrid(
    const typename GridT::ValueType& background = openvdb::zeroVal<typename GridT::ValueType>()) {
  openvdb::initialize();  // registers the standard types; idempotent
  typename GridT::Ptr grid =
      openvdb::gridPtrCast<GridT>(openvdb::GridBase::createGrid(GridT::gridType()));
  // (Null only if another class were registered under GridT's name.)
  if (!grid)
    throw std::logic_error("OpenVDB's grid type " + GridT::gridType() + " is another class");
  grid->tree().root().setBackground(background, /*updateChildNodes=*/false);
  return grid;
}

}  // namespace tickfx
