// What SocketCanBus decides without a CAN socket: the errors for interfaces that are missing or
// not CAN (these checks precede socket(AF_CAN), so they hold on kernels without CAN), and the
// conversion of what the kernel hands us. Real sockets: tests/bus (label vcan).
#include "ranger_can/transport/socketcan_bus.hpp"

#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <net/if.h>

#include <cstring>

#include "ranger_can/transport/error_frame.hpp"

namespace ranger {
namespace {

TEST(SocketCanOpen, MissingInterfaceIsNamed) {
  auto r = SocketCanBus::open("rcan_nothere0");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, Errc::kNoSuchInterface);
  EXPECT_NE(r.error().message.find("'rcan_nothere0' does not exist"), std::string::npos)
      << r.error().message;
  // It says what a user can do about it: list the interfaces, or (a kernel without CAN) load
  // CAN support and bring the interface up. Never a pointer at the project's own test VM.
  const std::string& m = r.error().message;
  const bool lists = m.find("`ip link show`") != std::string::npos;
  const bool loads =
      m.find("`sudo modprobe can-raw`") != std::string::npos &&
      m.find("`sudo ip link set rcan_nothere0 up type can bitrate 500000`") != std::string::npos;
  EXPECT_TRUE(lists || loads) << m;
  EXPECT_EQ(m.find("tests/vm"), std::string::npos) << m;
}

TEST(SocketCanOpen, OverlongAndEmptyNamesAreRefused) {
  auto long_name = SocketCanBus::open("a_name_much_too_long_for_linux");
  ASSERT_FALSE(long_name.ok());
  EXPECT_EQ(long_name.error().code, Errc::kNoSuchInterface);
  EXPECT_NE(long_name.error().message.find("a_name_much_too_long_for_linux"), std::string::npos);
  auto empty = SocketCanBus::open("");
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.error().code, Errc::kInvalidArgument);
}

TEST(SocketCanOpen, LoopbackNetworkInterfaceIsNotCan) {
  ASSERT_NE(::if_nametoindex("lo"), 0u) << "every network namespace has 'lo'";
  auto r = SocketCanBus::open("lo");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, Errc::kNotCanInterface) << r.error().message;
  EXPECT_NE(r.error().message.find("'lo' is not a CAN interface"), std::string::npos)
      << r.error().message;
}

struct can_frame kernel_frame(canid_t id, std::uint8_t dlc) {
  struct can_frame kf;
  std::memset(&kf, 0, sizeof kf);
  kf.can_id = id;
  kf.can_dlc = dlc;
  for (int i = 0; i < 8; ++i)
    kf.data[i] = static_cast<std::uint8_t>(0x10 + i);
  return kf;
}

TEST(SocketCanFrames, DataFrameKeepsOnlyItsDlcBytes) {
  auto r = socketcan::from_kernel(kernel_frame(0x221, 3), sizeof(struct can_frame), "vcan0");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->id, 0x221u);
  EXPECT_EQ(r->dlc, 3);
  EXPECT_FALSE(r->is_error);
  EXPECT_EQ(r->data[2], 0x12);
  EXPECT_EQ(r->data[3], 0) << "bytes past the DLC are zero";
}

TEST(SocketCanFrames, DlcAboveEightIsRejectedNotCopied) {
  auto r = socketcan::from_kernel(kernel_frame(0x221, 15), sizeof(struct can_frame), "can0");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, Errc::kBadDlc);
  EXPECT_NE(r.error().message.find("can0: frame 0x221 has DLC 15"), std::string::npos)
      << r.error().message;
}

TEST(SocketCanFrames, WrongSizeExtendedAndRemoteFramesAreRejected) {
  auto fd_sized = socketcan::from_kernel(kernel_frame(0x221, 8), 72, "can0");
  ASSERT_FALSE(fd_sized.ok());
  EXPECT_NE(fd_sized.error().message.find("72 bytes"), std::string::npos);

  auto eff = socketcan::from_kernel(kernel_frame(CAN_EFF_FLAG | 0x18FF0000, 8),
                                    sizeof(struct can_frame), "can0");
  ASSERT_FALSE(eff.ok());
  EXPECT_EQ(eff.error().code, Errc::kUnknownId);

  auto rtr = socketcan::from_kernel(kernel_frame(CAN_RTR_FLAG | 0x221, 0), sizeof(struct can_frame),
                                    "can0");
  ASSERT_FALSE(rtr.ok());
}

TEST(SocketCanFrames, ErrorFramesKeepTheirClassBits) {
  auto r = socketcan::from_kernel(kernel_frame(CAN_ERR_FLAG | can_error::kBusOff, 8),
                                  sizeof(struct can_frame), "can0");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_TRUE(r->is_error);
  EXPECT_EQ(r->id, can_error::kBusOff);
}

TEST(SocketCanFrames, ToKernelAndBackIsIdentity) {
  CanFrame f;
  f.id = 0x111;
  f.dlc = 8;
  f.data = {1, 2, 3, 4, 5, 6, 7, 8};
  const struct can_frame kf = socketcan::to_kernel(f);
  EXPECT_EQ(kf.can_id, 0x111u);
  auto back = socketcan::from_kernel(kf, sizeof kf, "can0");
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(*back, f);

  const struct can_frame err = socketcan::to_kernel(can_error::make(can_error::kBusOff));
  EXPECT_EQ(err.can_id, CAN_ERR_FLAG | CAN_ERR_BUSOFF);
}

}  // namespace
}  // namespace ranger
