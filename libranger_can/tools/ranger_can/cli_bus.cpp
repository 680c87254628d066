#include "cli_bus.hpp"

#include <map>
#include <mutex>

#include "ranger_can/transport/socketcan_bus.hpp"

namespace ranger::cli {

namespace {
std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}
std::map<std::string, std::shared_ptr<LoopbackNetwork>>& registry() {
  static std::map<std::string, std::shared_ptr<LoopbackNetwork>> r;
  return r;
}
}  // namespace

void register_loopback_interface(std::shared_ptr<LoopbackNetwork> network) {
  if (!network) return;
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry()[network->interface()] = std::move(network);
}

void unregister_loopback_interface(const std::string& name) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry().erase(name);
}

Result<std::unique_ptr<Bus>> open_interface(const std::string& iface) {
  std::shared_ptr<LoopbackNetwork> network;
  {
    std::lock_guard<std::mutex> lock(registry_mutex());
    auto it = registry().find(iface);
    if (it != registry().end()) network = it->second;
  }
  if (network) {
    auto bus = network->open(iface);
    if (!bus) return bus.error();
    return std::unique_ptr<Bus>(std::move(*bus));
  }
  auto bus = SocketCanBus::open(iface);
  if (!bus) return bus.error();
  return std::unique_ptr<Bus>(std::move(*bus));
}

}  // namespace ranger::cli
