// yaml-cpp's Load with a bound on the work it does: the one way YAML text is
// parsed in navimpact (ConfigNode::parse and the scenario metadata of rawlogs).
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace navimpact {

/// Every document of @p text, as YAML::LoadAll parses them. yaml-cpp 0.7 does
/// not come to an end on some malformed text (a 61-byte file of two comment
/// lines and "  , nor@th(4t" made it create nodes until memory ran out): the
/// text is first parsed without building nodes, counting the parser's events,
/// which are never more than a few per byte of real YAML (a node takes at
/// least one byte: `[,,]`, `- `, `*a`); beyond 4 per byte + 64 the parse is
/// given up with a YAML::ParserException at the mark it had reached.
std::vector<YAML::Node> loadAllYaml(const std::string& text);

/// The first document of @p text (YAML::Load), with the bound of loadAllYaml.
YAML::Node loadYaml(const std::string& text);

}  // namespace navimpact
