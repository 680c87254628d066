// ranger_base/RangerNodelet: the RANGER driver as a nodelet, for a manager whose other nodelets
// use its odometry, joint states or TF without serialisation (every message is published as a
// shared pointer). The same ranger_base::RangerNode as the executable ranger_base_node, created
// the same way (RangerNode::from_parameters from the nodelet's private namespace); unloading it
// stops the chassis (the zero motion command, logged and published on cmd_vel_out) like the
// executable's shutdown.
//
// Bad parameters: the nodelet logs every problem and stays loaded without a driver (a nodelet
// cannot end its manager); `rosrun nodelet nodelet unload` removes it.
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>
#include <sstream>
#include <string>

#include "ranger_base/ranger_node.hpp"

namespace ranger_base {

class RangerNodelet : public nodelet::Nodelet {
 public:
  RangerNodelet() = default;
  ~RangerNodelet() override {
    if (node_) node_->shutdown();
  }

 private:
  void onInit() override {
    auto node = RangerNode::from_parameters(getNodeHandle(), getPrivateNodeHandle());
    if (!node) {
      std::istringstream lines(node.error().message);
      for (std::string line; std::getline(lines, line);)
        NODELET_FATAL("%s", line.c_str());
      NODELET_FATAL("%s not started: fix the above and load it again", getName().c_str());
      return;
    }
    node_ = std::move(*node);
    node_->start();
  }

  std::unique_ptr<RangerNode> node_;
};

}  // namespace ranger_base

PLUGINLIB_EXPORT_CLASS(ranger_base::RangerNodelet, nodelet::Nodelet)
