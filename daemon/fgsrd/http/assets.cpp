#include "assets.hpp"

#include <string>

extern "C" {
extern const char fgsr_asset_dashboard_html[], fgsr_asset_dashboard_html_end[];
extern const char fgsr_asset_chart_js[], fgsr_asset_chart_js_end[];
}

namespace fgsr::dashboard {

std::string_view page() {
    return {fgsr_asset_dashboard_html, size_t(fgsr_asset_dashboard_html_end - fgsr_asset_dashboard_html)};
}

std::string_view chart_js() {
    return {fgsr_asset_chart_js, size_t(fgsr_asset_chart_js_end - fgsr_asset_chart_js)};
}

namespace {

void replace_once(std::string& s, std::string_view what, std::string_view with) {
    const size_t at = s.find(what);
    if (at != std::string::npos) s.replace(at, what.size(), with);
}

} // namespace

std::string standalone_page(std::string_view data_script) {
    std::string html(page());
    std::string inline_chart = "<script>";
    // A "</script" inside the library would end the element early.
    std::string js(chart_js());
    for (size_t at = 0; (at = js.find("</script", at)) != std::string::npos; at += 2) js.replace(at, 2, "<\\/");
    inline_chart += js;
    inline_chart += "</script>";
    replace_once(html, "<script src=\"chart.min.js\"></script>", inline_chart);
    replace_once(html, "<!--FGSR_DATA-->", data_script);
    return html;
}

} // namespace fgsr::dashboard
