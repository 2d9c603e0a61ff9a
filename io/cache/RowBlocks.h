// Cache bodies made in parallel and written in order.
#pragma once

#include <cstddef>
#include <functional>
#include <ostream>

namespace tickfx::io {

/// Writes rows [begin, end) at `bytes`, at most maxBytesPerRow a row (see writeRowsInBlocks),
/// and returns how many bytes it wrote.
using RowFormatter = std::function<std::size_t(std::size_t begin, std::size_t end, char* bytes)>;

/// Writes rows [0, rows) to `out`, made block by block by `format`: blocks of `rowsPerBlock`
/// rows, fixed by the row count alone, are formatted in parallel (TBB, within the calling
/// thread's limits) and written in row order, so the bytes never depend on the thread count and
/// formatting overlaps writing. At most twice as many blocks as threads are in memory at once,
/// each of rowsPerBlock · maxBytesPerRow bytes. Stops early once `out` has failed (the caller
/// reports the stream's error); whatever `format` throws is passed on.
void writeRowsInBlocks(std::ostream& out, std::size_t rows, std::size_t rowsPerBlock,
                       std::size_t maxBytesPerRow, const RowFormatter& format);

}  // namespace tickfx::io
