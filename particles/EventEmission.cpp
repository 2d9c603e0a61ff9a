#include "particles/EventEmission.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "particles/Assert.h"
#include "particles/NonfiniteState.h"
#include "particles/ParallelFor.h"

namespace tickfx {
namespace {

// The pool columns an attribute name stands for: Cd's three channels, a vector's three
// components when `columns` holds them (hitpos → hitpos_x, _y, _z), else the name itself.
std::vector<std::string> columnsOfName(const std::string& name,
                                       const std::vector<std::string>& columns) {
  const std::array<std::string, 3> vector = vectorColumnNames(name);
  if (name == "Cd" || std::find(columns.begin(), columns.end(), vector[0]) != columns.end()) {
    return {vector.begin(), vector.end()};
  }
  return {name};
}

int indexOfName(const std::vector<EmitterSettings>& emitters, const std::string& name) {
  for (std::size_t i = 0; i < emitters.size(); ++i) {
    if (emitters[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

// Joins per-block lists in block order, copying each block's part in parallel.
template <typename T>
std::vector<T> join(const std::vector<std::vector<T>>& blocks) {
  std::vector<std::size_t> offset(blocks.size() + 1, 0);
  for (std::size_t b = 0; b < blocks.size(); ++b) offset[b + 1] = offset[b] + blocks[b].size();
  std::vector<T> out(offset.back());
  parallelForTasks(blocks.size(), [&](std::size_t b) {
    std::copy(blocks[b].begin(), blocks[b].end(),
              out.begin() + static_cast<std::ptrdiff_t>(offset[b]));
  });
  return out;
}

// A birth or a death: the event at row `row`'s state (its position and velocity now).
ParticleEvent rowEvent(const ParticlePool& pool, std::size_t row, int emitter, EmitterEvent kind) {
  const auto r = static_cast<Eigen::Index>(row);
  ParticleEvent event;
  event.parentEmitter = static_cast<std::uint32_t>(emitter);
  event.kind = kind;
  event.position =
      Eigen::Vector3f(pool.position().x[r], pool.position().y[r], pool.position().z[r]);
  event.velocity =
      Eigen::Vector3f(pool.velocity().x[r], pool.velocity().y[r], pool.velocity().z[r]);
  return event;
}

}  // namespace

SettingProblems validateSubEmitters(const std::vector<EmitterSettings>& emitters,
                                    const std::vector<std::string>& columns) {
  SettingProblems out;
  for (std::size_t i = 0; i < emitters.size(); ++i) {
    const SubEmitterSettings& sub = emitters[i].sub;
    if (sub.parent.empty()) continue;
    const std::string key = std::to_string(i) + ".parent";
    const int parent = indexOfName(emitters, sub.parent);
    if (parent < 0) {
      out.push_back({key, "\"" + sub.parent + "\" is not the name of an emitter",
                     "the name of another [[emitters]] entry"});
      continue;
    }
    // Up the chain of parents: back to i is a cycle; past the depth bound is too deep.
    std::string chain = "\"" + emitters[i].name + "\"";
    int at = parent;
    int depth = 1;
    bool bad = false;
    while (at >= 0) {
      chain += " -> \"" + emitters[static_cast<std::size_t>(at)].name + "\"";
      if (static_cast<std::size_t>(at) == i) {
        out.push_back({key, chain + " is a cycle of parents",
                       "a chain of parents ending at an "
                       "emitter that has none"});
        bad = true;
        break;
      }
      const std::string& up = emitters[static_cast<std::size_t>(at)].sub.parent;
      if (up.empty()) break;
      at = indexOfName(emitters, up);
      if (++depth > kMaxSubEmitterDepth) {
        out.push_back(
            {key,
             "makes a chain of more than " + std::to_string(kMaxSubEmitterDepth) + " sub-emitters",
             "at most " + std::to_string(kMaxSubEmitterDepth) + " generations"});
        bad = true;
        break;
      }
    }
    if (bad) continue;
    // What the parent has to give: its declared and inherited attributes, and the pool's columns.
    const EmitterSettings& p = emitters[static_cast<std::size_t>(parent)];
    std::vector<std::string> has = columns;
    for (const LifeAttributeSettings& a : p.attributes) {
      for (const std::string& c : a.columnNames()) has.push_back(c);
    }
    for (const std::string& n : p.sub.inherit) {
      for (const std::string& c : columnsOfName(n, columns)) has.push_back(c);
    }
    for (std::size_t k = 0; k < sub.inherit.size(); ++k) {
      for (const std::string& c : columnsOfName(sub.inherit[k], columns)) {
        if (std::find(has.begin(), has.end(), c) == has.end()) {
          out.push_back(
              {std::to_string(i) + ".inherit." + std::to_string(k),
               "\"" + sub.inherit[k] + "\" is not an attribute of the parent \"" + p.name + "\"",
               "an attribute the parent declares or inherits, or a hit attribute"});
          break;
        }
      }
    }
  }
  return out;
}

EventEmission::EventEmission(const std::vector<Emitter>& emitters,
                             const LifeAttributeSet* attributes, std::uint64_t seed,
                             ParticlePool& pool)
    : emitters_(&emitters), attributes_(attributes), seed_(seed) {
  std::vector<EmitterSettings> settings;
  for (const Emitter& e : emitters) settings.push_back(e.settings());
  for (EmitterSettings& s : settings) s.shape = PointShape{};  // no point lists copied
  bool collisions = false;
  for (const EmitterSettings& s : settings) collisions |= s.sub.on == EmitterEvent::Collision;
  if (collisions) pool.addAttribute(kContactsColumn, 0.0f);
  std::vector<std::string> columns;
  for (std::size_t a = 0; a < pool.attributeCount(); ++a) columns.push_back(pool.attributeName(a));
  const SettingProblems problems = validateSubEmitters(settings, columns);
  if (!problems.empty()) throw std::invalid_argument("emitters." + problems.front().text());

  for (auto& perKind : listeners_) perKind.resize(emitters.size());
  for (std::size_t i = 0; i < settings.size(); ++i) {
    const SubEmitterSettings& sub = settings[i].sub;
    if (sub.parent.empty()) continue;
    ++subEmitters_;
    Listener listener{static_cast<std::uint32_t>(i), {}};
    for (const std::string& name : sub.inherit) {
      for (const std::string& c : columnsOfName(name, columns)) {
        auto it = std::find(inherited_.begin(), inherited_.end(), c);
        if (it == inherited_.end()) it = inherited_.insert(inherited_.end(), c);
        listener.inherit.push_back(static_cast<std::size_t>(it - inherited_.begin()));
      }
    }
    const auto parent = static_cast<std::size_t>(indexOfName(settings, sub.parent));
    const auto kind = static_cast<std::size_t>(sub.on);
    listeners_[kind][parent].push_back(std::move(listener));
    listening_[kind] = true;
  }
  for (const std::string& c : inherited_) {
    pool.addAttribute(c, LifeAttributeSettings::defaultValue(c));
    inheritedLife_.push_back(attributes_ != nullptr ? attributes_->find(c) : -1);
  }
}

EventEmission::Rows EventEmission::rowsOf(const ParticlePool& pool) const {
  Rows rows{pool, LifeAttributeSet::emitterColumn(pool), {}};
  for (const std::string& c : inherited_) {
    rows.inherited.push_back(pool.attribute(pool.findAttribute(c)).data());
  }
  return rows;
}

int EventEmission::listened(const Rows& rows, std::size_t row, EmitterEvent kind) const {
  const int e = LifeAttributeSet::emitterOf(rows.emitters, row);
  return e >= 0 && !listeners(static_cast<std::uint32_t>(e), kind).empty() ? e : -1;
}

void EventEmission::record(const Rows& rows, std::size_t row, ParticleEvent event,
                           std::vector<ParticleEvent>& events, std::vector<float>& values) const {
  const ParticlePool& pool = rows.pool;
  event.parentId = pool.id()[row];
  events.push_back(event);
  const auto r = static_cast<Eigen::Index>(row);
  for (std::size_t j = 0; j < inherited_.size(); ++j) {
    const float stored = rows.inherited[j][row];
    values.push_back(
        inheritedLife_[j] < 0
            ? stored
            : attributes_->rowValue(inheritedLife_[j], static_cast<int>(event.parentEmitter),
                                    event.parentId, pool.age(row), pool.lifetime()[r], stored));
  }
}

EventEmission::EventList EventEmission::births(const ParticlePool& pool, std::size_t begin,
                                               std::size_t end) const {
  const Rows rows = rowsOf(pool);
  const std::size_t blocks = (end - begin + kParallelBlockRows - 1) / kParallelBlockRows;
  std::vector<std::vector<ParticleEvent>> events(blocks);
  std::vector<std::vector<float>> values(blocks);
  parallelForTasks(blocks, [&](std::size_t b) {
    const std::size_t from = begin + b * kParallelBlockRows;
    const std::size_t to = std::min(end, from + kParallelBlockRows);
    for (std::size_t i = from; i < to; ++i) {
      const int e = listened(rows, i, EmitterEvent::Birth);
      if (e >= 0) record(rows, i, rowEvent(pool, i, e, EmitterEvent::Birth), events[b], values[b]);
    }
  });
  return EventList{join(events), join(values)};
}

void EventEmission::gather(const ParticlePool& pool,
                           std::span<const std::vector<ContactRecord>> contacts) {
  pending_.clear();
  pendingValues_.clear();
  const bool deaths = listensTo(EmitterEvent::Death);
  const bool hits = listensTo(EmitterEvent::Collision) && !contacts.empty();
  if (!deaths && !hits) return;
  const std::size_t n = pool.size();
  const std::size_t blocks = (n + kParallelBlockRows - 1) / kParallelBlockRows;
  const Rows rows = rowsOf(pool);
  const std::uint8_t* dead = pool.dead().data();
  std::vector<std::vector<ParticleEvent>> events(blocks);
  std::vector<std::vector<float>> values(blocks);
  parallelForTasks(blocks, [&](std::size_t b) {
    const std::size_t begin = b * kParallelBlockRows, end = std::min(n, begin + kParallelBlockRows);
    static const std::vector<ContactRecord> kNone;
    const std::vector<ContactRecord>& list = hits && b < contacts.size() ? contacts[b] : kNone;
    std::size_t c = 0;
    // The contacts of rows up to `row`, in row order (each row's in the order they happened).
    const auto contactsThrough = [&](std::size_t row) {
      for (; c < list.size() && list[c].row <= row; ++c) {
        const ContactRecord& k = list[c];
        const int e = listened(rows, k.row, EmitterEvent::Collision);
        if (e < 0) continue;
        ParticleEvent event;
        event.parentEmitter = static_cast<std::uint32_t>(e);
        event.kind = EmitterEvent::Collision;
        event.ordinal = k.ordinal;
        event.position = k.point;
        event.velocity = k.velocity;
        event.normal = k.normal;
        record(rows, k.row, event, events[b], values[b]);
      }
    };
    if (deaths) {
      for (std::size_t i = begin; i < end; ++i) {
        if ((i - begin) % 8 == 0 && i + 8 <= end) {
          std::uint64_t eight = 0;
          std::memcpy(&eight, dead + i, sizeof eight);
          if (eight == 0) {
            i += 7;
            continue;
          }
        }
        // A non-finite kill is no death: its state is not a place to emit from.
        if (dead[i] == 0 || (dead[i] & NonfiniteCheck::kFlag) != 0) continue;
        contactsThrough(i);
        const int e = listened(rows, i, EmitterEvent::Death);
        if (e >= 0)
          record(rows, i, rowEvent(pool, i, e, EmitterEvent::Death), events[b], values[b]);
      }
    }
    contactsThrough(end);
  });
  pending_ = join(events);
  pendingValues_ = join(values);
}

void EventEmission::spawnChildren(ParticlePool& pool, std::int64_t tick,
                                  const EventList& list) const {
  const std::size_t n = list.events.size();
  if (n == 0) return;
  const std::vector<Emitter>& emitters = *emitters_;
  const auto childrenOf = [&](const ParticleEvent& event) {
    std::uint64_t count = 0;
    for (const Listener& l : listeners(event.parentEmitter, event.kind)) {
      count += emitters[l.emitter].childCount(seed_, event);
    }
    return count;
  };
  // Children per event, then where each event's first child goes: a sum in event order.
  std::vector<std::uint64_t> offset(n + 1, 0);
  parallelForRows(n, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) offset[i + 1] = childrenOf(list.events[i]);
  });
  for (std::size_t i = 0; i < n; ++i) offset[i + 1] += offset[i];
  const std::uint64_t total = offset[n];
  const std::uint64_t room = pool.maxParticles() - pool.size();
  const std::uint64_t kept = std::min(total, room);
  const std::size_t first = pool.appendRows(static_cast<std::size_t>(kept), tick);
  pool.refuseSpawns(total - kept);
  if (kept == 0) return;
  float* const emitterColumn = pool.attribute(pool.findAttribute(kEmitterColumn)).data();
  std::vector<float*> inherited;
  for (const std::string& c : inherited_)
    inherited.push_back(pool.attribute(pool.findAttribute(c)).data());
  const std::size_t stride = inherited_.size();
  parallelForRows(n, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e && offset[i] < kept; ++i) {
      const ParticleEvent& event = list.events[i];
      std::uint64_t k = offset[i];
      for (const Listener& l : listeners(event.parentEmitter, event.kind)) {
        const Emitter& child = emitters[l.emitter];
        const std::uint64_t count = child.childCount(seed_, event);
        for (std::uint64_t c = 0; c < count && k < kept; ++c, ++k) {
          const std::size_t row = first + static_cast<std::size_t>(k);
          pool.setRow(row, child.sampleChild(seed_, event, c));
          emitterColumn[row] = static_cast<float>(l.emitter);
          for (const std::size_t j : l.inherit) inherited[j][row] = list.values[i * stride + j];
        }
      }
    }
  });
}

void EventEmission::spawn(ParticlePool& pool, std::int64_t tick, std::size_t firstNew) {
  if (empty()) return;
  if (!pending_.empty()) {
    const EventList list{std::move(pending_), std::move(pendingValues_)};
    pending_.clear();
    pendingValues_.clear();
    spawnChildren(pool, tick, list);
  }
  if (!listensTo(EmitterEvent::Birth)) return;
  // Round after round: the children of the births so far may be parents of birth events too; a
  // chain of parents is at most kMaxSubEmitterDepth long.
  std::size_t from = firstNew;
  for (int round = 0; round <= kMaxSubEmitterDepth && from < pool.size(); ++round) {
    const std::size_t to = pool.size();
    spawnChildren(pool, tick, births(pool, from, to));
    from = to;
  }
}

void EventEmission::restorePending(std::vector<ParticleEvent> events, std::vector<float> values) {
  TICKFX_ASSERT(values.size() == events.size() * inherited_.size(),
                "pending events restored with the wrong number of inherited values");
  pending_ = std::move(events);
  pendingValues_ = std::move(values);
}

}  // namespace tickfx
