// Starts Foxglove Studio (globals of the @foxglove/studio-base bundle) on the page's query:
//   ?ws=ws://127.0.0.1:PORT   the agrisim Foxglove server to connect to
//   &layout=/layout.json      the layout to open (the test serves one 3-D panel of
//                             assets/foxglove_layout.json)
// Studio's own web app (packages/studio-web) is not on npm, so this page supplies the three
// things that app does: settings kept in memory, a layout store holding the one layout, and
// the Foxglove WebSocket data source opened from a deep link.
(async () => {
  const query = new URLSearchParams(location.search);
  const wsUrl = query.get("ws");
  const layoutData = await (await fetch(query.get("layout"))).json();

  // Subprotocol bridge. Studio 1.48 (@foxglove/ws-protocol 0.5) asks for
  // "foxglove.websocket.v1"; agrisim's server (the `foxglove` crate 0.30) speaks the same
  // messages under their newer name "foxglove.sdk.v1" and accepts only that name. Studio opens
  // the socket in a Web Worker, telling it {type: "open", data: {wsUrl, protocols}} and
  // checking the protocol of its {type: "open", protocol} answer, so the rename is done on
  // those two messages. It is done here, in the test's page, not in agrisim, so that agrisim
  // serves only the protocol its server library implements.
  const OLD = "foxglove.websocket.v1", NEW = "foxglove.sdk.v1";
  const NativeWorker = window.Worker;
  window.agrisimBridge = { renamedRequests: 0, renamedAnswers: 0 };
  window.Worker = class extends NativeWorker {
    postMessage(msg, ...rest) {
      if (msg && msg.type === "open" && msg.data && Array.isArray(msg.data.protocols) && msg.data.protocols.includes(OLD)) {
        msg = { ...msg, data: { ...msg.data, protocols: msg.data.protocols.map((p) => (p === OLD ? NEW : p)) } };
        window.agrisimBridge.renamedRequests += 1;
      }
      return super.postMessage(msg, ...rest);
    }
    set onmessage(handler) {
      super.onmessage = handler && ((event) => {
        if (event.data && event.data.type === "open" && event.data.protocol === NEW) {
          window.agrisimBridge.renamedAnswers += 1;
          return handler({ data: { ...event.data, protocol: OLD } });
        }
        return handler(event);
      });
    }
    get onmessage() {
      return super.onmessage;
    }
  };

  // Settings, in memory: a fresh profile each time.
  const settings = new Map();
  const listeners = new Map();
  const appConfiguration = {
    get: (key) => settings.get(key),
    set: async (key, value) => {
      settings.set(key, value);
      for (const cb of listeners.get(key) ?? []) cb(value);
    },
    addChangeListener: (key, cb) => listeners.set(key, [...(listeners.get(key) ?? []), cb]),
    removeChangeListener: (key, cb) => listeners.set(key, (listeners.get(key) ?? []).filter((x) => x !== cb)),
  };

  // The layout store: the given layout, selected through the user profile Studio reads.
  const now = new Date(0).toISOString();
  const layouts = new Map();
  layouts.set("agrisim", {
    id: "agrisim",
    name: "agrisim",
    permission: "CREATOR_WRITE",
    baseline: { data: layoutData, savedAt: now },
    working: undefined,
    syncInfo: undefined,
  });
  localStorage.setItem("studio.profile-data", JSON.stringify({ currentLayoutId: "agrisim" }));
  const layoutStorage = {
    list: async () => [...layouts.values()],
    get: async (_ns, id) => layouts.get(id),
    put: async (_ns, layout) => {
      layouts.set(layout.id, layout);
      return layout;
    },
    delete: async (_ns, id) => {
      layouts.delete(id);
    },
    importLayouts: async () => {},
  };

  await initI18n();
  const deepLink = new URL(location.href);
  deepLink.search = new URLSearchParams({ ds: "foxglove-websocket", "ds.url": wsUrl }).toString();
  ReactDOM.render(
    React.createElement(App, {
      deepLinks: [deepLink.href],
      appConfiguration,
      dataSources: [new FoxgloveWebSocketDataSourceFactory()],
      layoutStorage,
      extensionLoaders: [],
      enableLaunchPreferenceScreen: false,
      enableGlobalCss: true,
    }),
    document.getElementById("root"),
  );
})().catch((e) => {
  console.error("agrisim viewer page: " + (e && e.stack ? e.stack : e));
});
