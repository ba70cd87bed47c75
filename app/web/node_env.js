// app/web/node_env.js: run before dynlab's wasm under node (--pre-js). The program sees the
// environment variables that choose where labs are read from (labs/lab.h), as the native one does.
Module['preRun'] = Module['preRun'] || [];
Module['preRun'].push(function () {
  ['DYNLAB_HOME', 'DYNLAB_LABS'].forEach(function (name) {
    if (process.env[name] !== undefined) ENV[name] = process.env[name];
  });
});
