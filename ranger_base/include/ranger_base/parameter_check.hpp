// `ranger_base_node --check-parameters`: the node's parameters checked before anything starts.
// ranger_bringup's launch files run it (through scripts/check_launch.py) while roslaunch reads
// them, so that parameters the node would refuse fail the launch itself: a non-zero exit status
// and every reason on the console, instead of a node that exits FATAL under a roslaunch that
// exits 0.
#pragma once

#include <iosfwd>
#include <string>

#include "ranger_base/parameters.hpp"

namespace ranger_base {

// The node's private parameters as one XML-RPC <value> (a struct, as the parameter server holds
// the private namespace; nested structs are '/'-separated names) in a MapParameterSource. The
// error names what could not be read.
ranger::Result<MapParameterSource> parameters_from_xml(const std::string& xml);

// Reads the parameters (parameters_from_xml) from `in` and checks them as the node does at start
// (load_parameters), a name it does not read being a problem too. Writes every problem to `err`,
// one per line; returns the exit status: 0 all good, 2 a problem.
int check_parameters(std::istream& in, std::ostream& err);

}  // namespace ranger_base
