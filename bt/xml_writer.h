#pragma once
// A small XML writer for plan files and node models (internal to bt/). It escapes every
// character that would not read back identically: & < > " ' and control characters
// (as numeric entities), so load -> save -> load is exact.

#include <string>
#include <string_view>
#include <vector>

namespace costar::bt {

class XmlWriter {
 public:
  XmlWriter() { out_ = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"; }
  void open(std::string_view name);
  void attribute(std::string_view name, std::string_view value);
  void text(std::string_view value);
  void close();
  const std::string& str() const { return out_; }

  static std::string escape(std::string_view value);

 private:
  void finishStartTag();
  std::string out_;
  std::vector<std::string> stack_;
  bool start_tag_open_ = false;
  bool has_children_ = false;
  bool has_text_ = false;
};

}  // namespace costar::bt
