// A pipeline's program built against an installed tickfx: load an effect file, advance it at the
// host's frame rate and copy what a renderer shows into the host's own buffer, once per frame.
//
//   embed EFFECT.toml   (prints the frame count, the particle count and the state hash; the same
//                        hash as `tickfx run EFFECT.toml --fps 30000/1001 --seconds 5 --hash`)
#include <algorithm>
#include <cstdio>
#include <vector>

#include <tickfx/tickfx.h>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: embed EFFECT.toml\n");
    return 2;
  }
  // One call from a file to a running system. Errors come back as values, in the CLI's format.
  tickfx::LoadedEffect fx = tickfx::loadEffect(argv[1]);
  if (!fx.ok()) {
    std::fputs(fx.text().c_str(), stderr);
    return 2;
  }
  tickfx::ParticleSystem& system = *fx.system;

  // NTSC video for 5 s: frames of 1001/30000 s (an exact number of flicks), the last one cut
  // short to end at 5 s, as `tickfx run --fps 30000/1001 --seconds 5` runs it.
  const tickfx::Flicks frame = tickfx::frameDuration({30000, 1001});
  const tickfx::Flicks length = 5 * tickfx::kFlicksPerSecond;

  std::vector<float> vertices;  // the renderer's buffer: x0 y0 z0 x1 y1 z1 …
  long long frames = 0;
  for (tickfx::Flicks shown = 0; shown < length; ++frames) {
    const tickfx::Flicks step = std::min(frame, length - shown);
    shown += step;
    const tickfx::AdvanceResult advanced = system.advance(step);
    if (advanced.ticksDropped > 0) std::fprintf(stderr, "frame %lld: ticks dropped\n", frames + 1);
    // Positions at the frame's own time (interpolated between ticks), straight into the buffer:
    // one copy, no temporary columns.
    vertices.resize(3 * system.pool().size());
    system.copyRenderPositions(
        tickfx::Vec3Destination::interleaved(vertices.data(), system.pool().size()));
  }
  std::printf("frames: %lld\n", frames);
  std::printf("particles: %zu\n", system.pool().size());
  std::printf("ticks: %lld\n", static_cast<long long>(system.tickCount()));
  std::printf("state-hash: %s\n", tickfx::hashToHex(tickfx::stateHash(system.pool())).c_str());
  return 0;
}
