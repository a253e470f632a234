-- wrk script: every connection waits PERIOD milliseconds after each answer
-- before its next request, the way a page or a script polling its job
-- does, instead of asking again at once.
--   wrk -c 200 -s bench/paced.lua URL -- PERIOD
local period = 100

function init(args)
    if args[1] then
        period = tonumber(args[1])
    end
end

function delay()
    return period
end
