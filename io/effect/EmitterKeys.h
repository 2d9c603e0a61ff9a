// Internal to the effect parser (not installed): the keys each kind of [[emitters]] entry reads
// (particle emitters and their shapes, file emitters, structures), and the messages for a key
// that belongs to another kind than the entry's.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace tickfx::io::detail {

// The keys of a file emitter (type "file"): a particle emitter's, with `file` for the shape.
const std::vector<std::string>& fileEmitterKeys();

// Shape → its parameters, to tell "does not apply here" from "unknown".
const std::map<std::string, std::vector<std::string>>& shapeKeys();

// Keys every structure type reads, then each type's own, in the order "expected for" lists
// them.
const std::vector<std::string>& structureCommonKeys();
const std::map<std::string, std::vector<std::string>>& structureKeys();

// The keys of a particle emitter (type "particles"), its shapes' parameters included.
const std::vector<std::string>& particleEmitterKeys();

// The keys of structure type `type`, "type" first.
std::vector<std::string> structureOwnKeys(const std::string& type);

// Key → why it does not apply, for TableReader::finish():
// on a particle emitter, the keys it does not have, naming the types that do;
std::map<std::string, std::string> notForStructureKeys();
// on a file emitter, the keys of particle emitters (shapes) and of structures;
std::map<std::string, std::string> notForFileEmitter();
// on a structure of `type`, the keys of particle emitters and of the other structure types.
std::map<std::string, std::string> notForStructure(const std::string& type);

}  // namespace tickfx::io::detail
