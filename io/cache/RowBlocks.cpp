#include "io/cache/RowBlocks.h"

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <memory>

#include "io/util/ProfiledTbb.h"

namespace tickfx::io {
namespace {

struct Block {
  std::size_t begin = 0;
  std::size_t end = 0;
  // Not zero-filled first: the formatter writes every byte that is written out.
  std::unique_ptr<char[]> bytes;
  std::size_t size = 0;
};

}  // namespace

void writeRowsInBlocks(std::ostream& out, std::size_t rows, std::size_t rowsPerBlock,
                       std::size_t maxBytesPerRow, const RowFormatter& format) {
  if (rows == 0) return;
  rowsPerBlock = std::max<std::size_t>(rowsPerBlock, 1);
  const std::size_t blocks = (rows + rowsPerBlock - 1) / rowsPerBlock;
  const std::size_t blockBytes = std::min(rows, rowsPerBlock) * maxBytesPerRow;
  // Shared, not owned raw: after an exception from `format` TBB drops the blocks in flight.
  using BlockPtr = std::shared_ptr<Block>;
  std::size_t next = 0;
  const auto tokens =
      static_cast<std::size_t>(2 * std::max(1, tbb::this_task_arena::max_concurrency()));
  const auto take = [&](tbb::flow_control& fc) -> BlockPtr {
    if (next == blocks || !out) {
      fc.stop();
      return nullptr;
    }
    auto block = std::make_shared<Block>();
    block->begin = next * rowsPerBlock;
    block->end = std::min(rows, block->begin + rowsPerBlock);
    ++next;
    return block;
  };
  const auto make = [&](BlockPtr block) {
    block->bytes = std::make_unique_for_overwrite<char[]>(blockBytes);
    block->size = format(block->begin, block->end, block->bytes.get());
    return block;
  };
  const auto put = [&](const BlockPtr& block) {
    if (out) out.write(block->bytes.get(), static_cast<std::streamsize>(block->size));
  };
  par::parallel_pipeline(
      tokens, tbb::make_filter<void, BlockPtr>(tbb::filter_mode::serial_in_order, take) &
                  tbb::make_filter<BlockPtr, BlockPtr>(tbb::filter_mode::parallel, make) &
                  tbb::make_filter<BlockPtr, void>(tbb::filter_mode::serial_in_order, put));
}

}  // namespace tickfx::io
