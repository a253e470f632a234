// A node:test reporter that counts the tests that ran (leaves only: a
// suite or a test with subtests is not counted again), prints "FAIL name"
// for each failure and "SKIP name: why" for each skipped test, and ends
// with "NAME: N passed, M failed, K skipped", NAME TK_SUMMARY_NAME's or
// "service" (a skipped test is not a
// passed one).  A test file that fails outside any test counts as one
// failure.
export default async function* summary(source) {
    let passed = 0;
    let failed = 0;
    let skipped = 0;
    const childSeen = [];
    for await (const event of source) {
        if (event.type !== 'test:pass' && event.type !== 'test:fail') continue;
        const { nesting, name, file, details } = event.data;
        const leaf = !childSeen[nesting + 1];
        childSeen[nesting + 1] = false;
        childSeen[nesting] = true;
        if (!leaf || details?.type === 'suite') continue;
        if (event.data.skip !== undefined && event.type === 'test:pass') {
            skipped++;
            yield `SKIP ${name}: ${event.data.skip === true ? 'skipped' : event.data.skip}\n`;
        } else if (event.type === 'test:pass') {
            passed++;
        } else {
            failed++;
            const where = file ? ` (${file.replace(/^.*\/tests\/[^/]+\//, '')})` : '';
            yield `FAIL ${name}${where}\n`;
        }
    }
    yield `${process.env.TK_SUMMARY_NAME ?? 'service'}: ${passed} passed, ${failed} failed, ${skipped} skipped\n`;
}
