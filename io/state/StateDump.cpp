#include "io/state/StateDump.h"

#include <cstdio>

#include "io/util/AtomicFile.h"

namespace tickfx::io {

void writeStateDump(const FrameData& frame, const std::filesystem::path& path) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "id,px,py,pz,vx,vy,vz,age\n";
    char line[320];
    const Vec3Column& p = frame.position;
    const Vec3Column& v = frame.velocity;
    for (std::size_t i = 0; i < frame.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      std::snprintf(line, sizeof line, "%llu,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
                    static_cast<unsigned long long>(frame.id[i]), static_cast<double>(p.x[r]),
                    static_cast<double>(p.y[r]), static_cast<double>(p.z[r]),
                    static_cast<double>(v.x[r]), static_cast<double>(v.y[r]),
                    static_cast<double>(v.z[r]), static_cast<double>(frame.age[r]));
      out << line;
    }
  });
}

}  // namespace tickfx::io
