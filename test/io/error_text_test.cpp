// One-line error text from exception texts (MRPT's carry a banner, a location and a call stack)
// and from bytes read out of a file.
#include "evidential_slam/io/error_text.h"

#include <gtest/gtest.h>

namespace evidential_slam {
namespace io {
namespace {

TEST(ErrorText, OneLineOfAnMrptException) {
  EXPECT_EQ(oneLineMessage("==== MRPT exception ====\nMessage: end-flag missing: There is a bug\n"
                           "Location: /build/CArchive.cpp:480: [internal_ReadObject]\n"
                           "Call stack backtrace:\n[0 ] 0x7f27 \n"),
            "end-flag missing: There is a bug");
  // An empty message: the wrapped exception's text is under "Location:".
  EXPECT_EQ(oneLineMessage("==== MRPT exception ====\nMessage: \nLocation: filesystem error: "
                           "cannot get file size: Operation not supported [/dev/zero\n"
                           "Call stack backtrace:\n[0 ] 0x7f27\n"),
            "filesystem error: cannot get file size: Operation not supported [/dev/zero");
  EXPECT_EQ(oneLineMessage("plain\ttext  with   spaces\nsecond line"), "plain text with spaces");
  EXPECT_EQ(oneLineMessage("==== MRPT exception ====\nCall stack backtrace:\n[0 ] x\n"),
            "(no message)");
  EXPECT_EQ(oneLineMessage(""), "(no message)");
}

TEST(ErrorText, NoRawBytesAndBoundedLength) {
  EXPECT_EQ(oneLineMessage(std::string("bad \x1b[2J\xff\x01 class", 16)), "bad ?[2J?? class");
  const std::string cut = oneLineMessage(std::string(500, 'x'), 20);
  EXPECT_EQ(cut, std::string(17, 'x') + "...");
  EXPECT_EQ(quotedForMessage(std::string("C\x01\xff\\ok", 6)), "'C\\x01\\xff\\x5cok'");
  EXPECT_EQ(quotedForMessage(std::string(100, 'a'), 5), "'aaaaa...'");
  EXPECT_EQ(quotedForMessage(""), "''");
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
