#include "io/StateDump.h"

#include <cstdio>

#include "io/AtomicFile.h"

namespace tickfx::io {

void writeStateDump(const ParticlePool& pool, const std::filesystem::path& path) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "id,px,py,pz,vx,vy,vz,age\n";
    char line[320];
    for (std::size_t i = 0; i < pool.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      std::snprintf(
          line, sizeof line, "%llu,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
          static_cast<unsigned long long>(pool.id()[i]), static_cast<double>(pool.position().x[r]),
          static_cast<double>(pool.position().y[r]), static_cast<double>(pool.position().z[r]),
          static_cast<double>(pool.velocity().x[r]), static_cast<double>(pool.velocity().y[r]),
          static_cast<double>(pool.velocity().z[r]), static_cast<double>(pool.age()[r]));
      out << line;
    }
  });
}

}  // namespace tickfx::io
