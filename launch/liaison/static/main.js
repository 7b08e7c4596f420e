// Which view this URL shows (Goby's "?_=/scope" internal paths, or "/scope"), then connect.
"use strict";

function currentView() {
  const internal = new URLSearchParams(location.search).get("_");
  const path = (internal || location.pathname).replace(/^\/+|\/+$/g, "");
  return ["scope", "commander", "map"].includes(path) ? path : "home";
}

(function start() {
  const view = currentView();
  document.getElementById(`view-${view}`).hidden = false;
  for (const link of document.querySelectorAll("nav a")) {
    if (link.dataset.view === view) link.classList.add("active");
  }
  Liaison.views = view === "home" ? [] : [view];
  if (view === "scope") Scope.init();
  if (view === "commander") Commander.init();
  if (view === "map") LiveMap.init();
  document.body.dataset.view = view;
  Liaison.connect();
})();
