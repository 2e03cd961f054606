// What the demo, its fixtures and the crowd page hang on `window` for the scripts that drive them
// in a browser (page.evaluate): the scripts read them, the pages define them.
interface Window {
  __demo: any;
  __crowd: any;
  __done: any;
}
