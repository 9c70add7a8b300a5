// Mounts Foxglove Studio's App with the layout under test as the only stored
// layout, and the data sources a file or URL can be opened with.
/* global React, ReactDOM */
"use strict";

// Settings kept in memory: nothing from a previous run changes this one.
class MemoryAppConfiguration {
  constructor(values) {
    this.values = new Map(Object.entries(values));
    this.listeners = new Map();
  }
  get(key) {
    return this.values.get(key);
  }
  async set(key, value) {
    this.values.set(key, value);
    for (const listener of this.listeners.get(key) ?? []) {
      listener(value);
    }
  }
  addChangeListener(key, cb) {
    const set = this.listeners.get(key) ?? new Set();
    set.add(cb);
    this.listeners.set(key, set);
  }
  removeChangeListener(key, cb) {
    this.listeners.get(key)?.delete(cb);
  }
}

// Layouts kept in memory, seeded with the one layout the check imports.
class MemoryLayoutStorage {
  constructor(layouts) {
    this.layouts = new Map(layouts.map((layout) => [layout.id, layout]));
  }
  async list() {
    return [...this.layouts.values()];
  }
  async get(_namespace, id) {
    return this.layouts.get(id);
  }
  async put(_namespace, layout) {
    this.layouts.set(layout.id, layout);
    return layout;
  }
  async delete(_namespace, id) {
    this.layouts.delete(id);
  }
  async importLayouts() {}
  async migrateUnnamespacedLayouts() {}
}

async function main() {
  const studio = window; // the bundle puts its exports on the global object
  const layoutData = await (await fetch("/layout.json")).json();
  const layout = {
    id: "a2ml",
    name: "a2ml (docs/foxglove_layout.json)",
    permission: "CREATOR_WRITE",
    baseline: { data: layoutData, savedAt: new Date().toISOString() },
    working: undefined,
    syncInfo: undefined,
  };
  studio.overwriteFetch();
  await studio.waitForFonts();
  await studio.initI18n();
  const dataSources = [
    new studio.McapLocalDataSourceFactory(),
    new studio.RemoteDataSourceFactory(),
  ];
  const app = React.createElement(studio.App, {
    deepLinks: [window.location.href],
    appConfiguration: new MemoryAppConfiguration({}),
    layoutStorage: new MemoryLayoutStorage([layout]),
    dataSources,
    extensionLoaders: [],
    enableLaunchPreferenceScreen: false,
    enableGlobalCss: true,
  });
  ReactDOM.render(app, document.getElementById("root"));
}

main().catch((error) => {
  console.error("a2ml root:", error);
  document.body.setAttribute("data-a2ml-error", String(error));
});
