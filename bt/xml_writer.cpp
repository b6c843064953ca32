#include "bt/xml_writer.h"

namespace costar::bt {

std::string XmlWriter::escape(std::string_view value) {
  std::string escaped;
  escaped.reserve(value.size());
  for (const char c : value) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
          static constexpr char kHex[] = "0123456789ABCDEF";
          escaped += "&#x";
          escaped += kHex[(static_cast<unsigned char>(c) >> 4) & 0xF];
          escaped += kHex[static_cast<unsigned char>(c) & 0xF];
          escaped += ';';
        } else {
          escaped += c;
        }
    }
  }
  return escaped;
}

void XmlWriter::finishStartTag() {
  if (start_tag_open_) {
    out_ += '>';
    start_tag_open_ = false;
  }
}

void XmlWriter::open(std::string_view name) {
  finishStartTag();
  if (!stack_.empty()) {
    out_ += '\n';
  }
  out_.append(2 * stack_.size(), ' ');
  out_ += '<';
  out_ += name;
  stack_.emplace_back(name);
  start_tag_open_ = true;
  has_children_ = false;
  has_text_ = false;
}

void XmlWriter::attribute(std::string_view name, std::string_view value) {
  out_ += ' ';
  out_ += name;
  out_ += "=\"";
  out_ += escape(value);
  out_ += '"';
}

void XmlWriter::text(std::string_view value) {
  finishStartTag();
  out_ += escape(value);
  has_text_ = true;
}

void XmlWriter::close() {
  const std::string name = stack_.back();
  stack_.pop_back();
  if (start_tag_open_) {
    out_ += "/>";
    start_tag_open_ = false;
  } else {
    if (!has_text_) {
      out_ += '\n';
      out_.append(2 * stack_.size(), ' ');
    }
    out_ += "</" + name + ">";
  }
  has_children_ = true;
  has_text_ = false;
  if (stack_.empty()) {
    out_ += '\n';
  }
}

}  // namespace costar::bt
