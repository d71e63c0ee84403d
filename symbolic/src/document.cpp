#include "backlash/symbolic/document.hpp"

#include "backlash/symbolic/escape.hpp"
#include "backlash/symbolic/pretty.hpp"

#include <algorithm>
#include <sstream>

namespace backlash::symbolic::doc {

Rich text(std::string s) { return {Span{Span::Kind::Text, std::move(s), ""}}; }
Rich math(std::string latex) { return {Span{Span::Kind::Math, std::move(latex), ""}}; }
Rich code(std::string s) { return {Span{Span::Kind::Code, std::move(s), ""}}; }
Rich bold(std::string s) { return {Span{Span::Kind::Bold, std::move(s), ""}}; }
Rich link(std::string s, std::string target) { return {Span{Span::Kind::Link, std::move(s), std::move(target)}}; }
Rich operator+(Rich a, const Rich& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

Block heading(int level, Rich content, std::string anchor) {
  Block b;
  b.kind = Block::Kind::Heading;
  b.level = level;
  b.content = std::move(content);
  b.anchor = std::move(anchor);
  return b;
}
Block paragraph(Rich content) {
  Block b;
  b.kind = Block::Kind::Paragraph;
  b.content = std::move(content);
  return b;
}
Block equation(std::string latex) {
  Block b;
  b.kind = Block::Kind::Equation;
  b.equation = std::move(latex);
  return b;
}
Block table(std::vector<Rich> header, std::vector<std::vector<Rich>> rows, std::string align, Rich caption) {
  Block b;
  b.kind = Block::Kind::Table;
  b.header = std::move(header);
  b.rows = std::move(rows);
  b.align = std::move(align);
  b.caption = std::move(caption);
  return b;
}
Block figure(std::string path, Rich caption) {
  Block b;
  b.kind = Block::Kind::Figure;
  b.figure = std::move(path);
  b.caption = std::move(caption);
  return b;
}
Block code_block(std::string language, std::string source) {
  Block b;
  b.kind = Block::Kind::Code;
  b.language = std::move(language);
  b.source = std::move(source);
  return b;
}
Block list(std::vector<Rich> items) {
  Block b;
  b.kind = Block::Kind::List;
  b.items = std::move(items);
  return b;
}

namespace {

// Inline math for Markdown: $`…`$ (GitHub and GitLab); a backtick cannot occur in it.
std::string markdown_math(const std::string& latex) {
  std::string m;
  for (char c : latex) m += (c == '`' ? '\'' : (c == '\n' ? ' ' : c));
  return "$`" + m + "`$";
}

std::string markdown_inline_code(const std::string& s) {
  std::string clean;
  for (char c : escape::valid_utf8(s)) clean += (static_cast<unsigned char>(c) < 0x20 || c == '|') ? ' ' : c;
  const std::string fence = clean.find('`') == std::string::npos ? "`" : "`` ";
  return fence + clean + (fence == "`" ? "`" : " ``");
}

std::string markdown_rich(const Rich& r, bool in_table) {
  std::string out;
  for (const Span& s : r) {
    switch (s.kind) {
      case Span::Kind::Text: out += escape::markdown_text(s.text); break;
      case Span::Kind::Math: {
        std::string m = markdown_math(s.text);
        if (in_table) {  // a bar would end the cell
          std::string safe;
          for (char c : m) safe += c == '|' ? std::string("\\vert ") : std::string(1, c);
          m = safe;
        }
        out += m;
        break;
      }
      case Span::Kind::Code: out += markdown_inline_code(s.text); break;
      case Span::Kind::Bold: out += "**" + escape::markdown_text(s.text) + "**"; break;
      case Span::Kind::Link: out += "[" + escape::markdown_text(s.text) + "](" + s.target + ")"; break;
    }
  }
  return out;
}

std::string latex_rich(const Rich& r) {
  std::string out;
  for (const Span& s : r) {
    switch (s.kind) {
      case Span::Kind::Text: out += escape::latex_text(s.text); break;
      case Span::Kind::Math: out += "$" + s.text + "$"; break;
      case Span::Kind::Code: out += "\\texttt{" + escape::latex_text(s.text) + "}"; break;
      case Span::Kind::Bold: out += "\\textbf{" + escape::latex_text(s.text) + "}"; break;
      case Span::Kind::Link: out += escape::latex_text(s.text); break;
    }
  }
  return out;
}

}  // namespace

std::string to_markdown(const Document& document, const MarkdownOptions& options) {
  std::ostringstream out;
  for (const Block& b : document) {
    switch (b.kind) {
      case Block::Kind::Heading:
        out << std::string(static_cast<std::size_t>(b.level), '#') << " " << markdown_rich(b.content, false) << "\n\n";
        break;
      case Block::Kind::Paragraph: out << markdown_rich(b.content, false) << "\n\n"; break;
      case Block::Kind::Equation: out << "```math\n" << b.equation << "\n```\n\n"; break;
      case Block::Kind::Table: {
        if (!b.caption.empty()) out << markdown_rich(b.caption, false) << "\n\n";
        out << "|";
        for (const Rich& h : b.header) out << " " << markdown_rich(h, true) << " |";
        out << "\n|";
        for (std::size_t i = 0; i < b.header.size(); ++i) {
          const char a = i < b.align.size() ? b.align[i] : 'l';
          out << (a == 'r' ? "---:" : (a == 'c' ? ":---:" : "---")) << "|";
        }
        out << "\n";
        for (const auto& row : b.rows) {
          out << "|";
          for (std::size_t i = 0; i < b.header.size(); ++i) out << " " << (i < row.size() ? markdown_rich(row[i], true) : "") << " |";
          out << "\n";
        }
        out << "\n";
        break;
      }
      case Block::Kind::Figure:
        out << "![" << escape::markdown_text([&] {
          std::string plain;
          for (const Span& s : b.caption) plain += s.text;
          return plain;
        }()) << "](" << options.root << b.figure << options.figure_extension << ")\n\n";
        out << "*" << markdown_rich(b.caption, false) << "*\n\n";
        break;
      case Block::Kind::Code: out << "```" << b.language << "\n" << b.source << (b.source.empty() || b.source.back() != '\n' ? "\n" : "") << "```\n\n"; break;
      case Block::Kind::List:
        for (const Rich& item : b.items) out << "- " << markdown_rich(item, false) << "\n";
        out << "\n";
        break;
    }
  }
  return out.str();
}

namespace {

// A code line for LaTeX's verbatim, which takes ASCII only: the Greek letters of the
// generated code's comments spelled out ("θm(t)" → "theta_m(t)", a dotted θ → "dtheta"),
// other control or non-ASCII bytes as '?'.
std::string verbatim_ascii(const std::string& line) {
  static const std::pair<const char*, const char*> letters[] = {
      {"\u03B8\u0307", "dtheta_"}, {"\u03B8", "theta_"}, {"\u03C9", "omega_"}, {"\u03C6", "phi"},
      {"\u03B7", "eta"},           {"\u2212", "-"},      {"\u00B7", "*"}};
  std::string out;
  for (std::size_t k = 0; k < line.size();) {
    bool replaced = false;
    for (const auto& [from, to] : letters) {
      const std::string f = from;
      if (line.compare(k, f.size(), f) == 0) {
        out += to;
        k += f.size();
        replaced = true;
        break;
      }
    }
    if (replaced) continue;
    const unsigned char c = static_cast<unsigned char>(line[k]);
    if (c >= 0x80) {  // the rest of an unknown UTF-8 sequence goes with it
      out += '?';
      for (++k; k < line.size() && (static_cast<unsigned char>(line[k]) & 0xC0) == 0x80;) ++k;
      continue;
    }
    out += (c < 0x20 && c != '\t') ? '?' : static_cast<char>(c);
    ++k;
  }
  return out;
}

}  // namespace

std::string to_latex(const Document& document, const LatexOptions& options) {
  static const char* sections[] = {"chapter", "section", "subsection", "subsubsection", "paragraph", "subparagraph"};
  std::ostringstream out;
  for (const Block& b : document) {
    switch (b.kind) {
      case Block::Kind::Heading: {
        int index = b.level + options.top_level - 1;
        if (index < 0) index = 0;
        if (index > 5) index = 5;
        out << "\\" << sections[index] << "{" << latex_rich(b.content) << "}";
        if (!b.anchor.empty()) out << "\\label{" << b.anchor << "}";
        out << "\n\n";
        break;
      }
      case Block::Kind::Paragraph: out << latex_rich(b.content) << "\n\n"; break;
      case Block::Kind::Equation: {
        const bool tagged = b.equation.find("\\tag{") != std::string::npos;
        // A line that no break between summands can bring within the text width (a single
        // wide fraction of the general solutions) is scaled down to fit; an untagged
        // equation only (a \tag cannot sit in a box), and never scaled up.
        std::size_t widest = 0;
        for (std::size_t from = 0; from <= b.equation.size();) {
          const std::size_t end = std::min(b.equation.find("\\\\", from), b.equation.size());
          widest = std::max(widest, pretty::visible_width(b.equation.substr(from, end - from)));
          from = end + 2;
        }
        if (!tagged && widest > 100)
          out << "\\begin{equation*}\n\\resizebox{\\ifdim\\width>\\linewidth\\linewidth\\else\\width\\fi}{!}{$\\displaystyle "
              << b.equation << "$}\n\\end{equation*}\n\n";
        else
          out << "\\begin{equation*}\n" << b.equation << "\n\\end{equation*}\n\n";
        break;
      }
      case Block::Kind::Table: {
        std::string align = b.align;
        while (align.size() < b.header.size()) align += 'l';
        if (!b.latex_columns.empty()) align = b.latex_columns;
        out << "{" << (b.small ? "\\footnotesize" : "\\small") << "\n\\begin{longtable}{" << align << "}\n";
        if (!b.caption.empty()) out << "\\caption*{" << latex_rich(b.caption) << "}\\\\\n";
        out << "\\toprule\n";
        for (std::size_t i = 0; i < b.header.size(); ++i) out << (i ? " & " : "") << latex_rich(b.header[i]);
        out << "\\\\\n\\midrule\n\\endhead\n";
        for (const auto& row : b.rows) {
          for (std::size_t i = 0; i < b.header.size(); ++i) out << (i ? " & " : "") << (i < row.size() ? latex_rich(row[i]) : "");
          out << "\\\\\n";
        }
        out << "\\bottomrule\n\\end{longtable}\n}\n\n";
        break;
      }
      case Block::Kind::Figure:
        out << "\\begin{figure}[H]\n\\centering\n\\includegraphics[width=\\linewidth]{" << b.figure << options.figure_extension
            << "}\n\\caption*{" << latex_rich(b.caption) << "}\n\\end{figure}\n\n";
        break;
      case Block::Kind::Code: {
        // verbatim: only an \end{verbatim} line could break it
        std::string source = b.source;
        std::string safe;
        std::istringstream lines(source);
        std::string line;
        std::size_t longest = 0;
        while (std::getline(lines, line)) {
          longest = std::max(longest, line.size());
          if (line.find("\\end{verbatim}") != std::string::npos) line = "  (line omitted)";
          safe += verbatim_ascii(line) + "\n";
        }
        // a verbatim line cannot wrap: past ~112 characters (the text width at 8 pt) the
        // block is set at 7 pt, which holds ~133
        out << (longest > 112 ? "{\\scriptsize" : "{\\footnotesize") << "\n\\begin{verbatim}\n" << safe << "\\end{verbatim}\n}\n\n";
        break;
      }
      case Block::Kind::List:
        out << "\\begin{itemize}\n";
        for (const Rich& item : b.items) out << "\\item " << latex_rich(item) << "\n";
        out << "\\end{itemize}\n\n";
        break;
    }
  }
  return out.str();
}

}  // namespace backlash::symbolic::doc
